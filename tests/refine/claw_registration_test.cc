// The claw registration recovers a known pose error from noisy depth, and
// says so when the claw is not in view.
#include "graspfill/refine/claw_registration.hpp"

#include <gtest/gtest.h>

#include "refine_fixtures.hpp"

namespace graspfill::refine {
namespace {

using graspfill::testing::AngleDeg;
using graspfill::testing::CameraError;
using graspfill::testing::ClawOffsetM;
using graspfill::testing::RenderFrame;
using graspfill::testing::TrueT_C_G;

class ClawRegistrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    claw_ = graspfill::testing::PosedClaw();
    raycaster_.AddMesh(claw_);
    raycaster_.Commit();
    registration_.SetClaw(claw_);
  }
  TriangleMesh claw_;
  Raycaster raycaster_;
  ClawRegistration registration_;
};

TEST_F(ClawRegistrationTest, RecoversAHandEyeSizedErrorFromNoisyDepth) {
  ASSERT_GT(registration_.model_points_G().size(), 5000u);
  const double thetas[] = {0.0, 0.7, 1.9, 3.0};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(thetas[k]);
    const DepthFrame frame = RenderFrame(raycaster_, truth, 0.001, 17 + k);
    // 3 mm and 1 deg about an axis through the camera: ~10 mm at the claw.
    const Eigen::Isometry3d initial =
        CameraError(3.0, Eigen::Vector3d(1, -2, 0.5), 1.0, Eigen::Vector3d(0.3, 1, -0.2)) * truth;
    ASSERT_GT(ClawOffsetM(initial, truth), 0.006);
    const RegistrationResult r = registration_.Register(frame, initial, 0.025);
    ASSERT_EQ(r.status, RegistrationStatus::kConverged) << RegistrationStatusName(r.status);
    EXPECT_LT(ClawOffsetM(r.T_C_G, truth), 0.0002) << "theta " << thetas[k];
    EXPECT_LT(AngleDeg(r.T_C_G, truth), 0.25) << "theta " << thetas[k];
    EXPECT_GT(r.matches, 300);
    EXPECT_LT(r.rms_m, 0.0015);
    // correction_C maps the initial pose onto the registered one.
    EXPECT_LT(ClawOffsetM(r.correction_C * initial, r.T_C_G), 1e-9);
  }
}

TEST_F(ClawRegistrationTest, ReportsAClawThatIsNotInView) {
  const Eigen::Isometry3d truth = TrueT_C_G(0.4);
  // The sphere alone (no claw rendered): what the pose predicts is not there.
  const DepthFrame no_claw = RenderFrame(raycaster_, truth, 0.001, 3, /*with_claw=*/false);
  const RegistrationResult r = registration_.Register(no_claw, truth, 0.008);
  EXPECT_NE(r.status, RegistrationStatus::kConverged);
  // No valid depth at all.
  DepthFrame empty = no_claw;
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), 0.0f);
  EXPECT_EQ(registration_.Register(empty, truth, 0.008).status, RegistrationStatus::kTooFewPoints);
  // A pose 10 cm off: the claw is elsewhere in the image.
  const DepthFrame frame = RenderFrame(raycaster_, truth, 0.001, 4);
  Eigen::Isometry3d jumped = truth;
  jumped.translation().x() += 0.10;
  EXPECT_NE(registration_.Register(frame, jumped, 0.008).status, RegistrationStatus::kConverged);
  // A claw never set.
  ClawRegistration unset;
  EXPECT_EQ(unset.Register(frame, truth, 0.008).status, RegistrationStatus::kNoClaw);
}

TEST(ClawRegistrationConfig, BadValuesAreRejected) {
  EXPECT_NO_THROW(ClawRegistrationConfig{}.Validate());
  ClawRegistrationConfig bad;
  bad.final_gate_m = 0.01;  // beyond the fine band
  EXPECT_THROW(ClawRegistration{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::refine
