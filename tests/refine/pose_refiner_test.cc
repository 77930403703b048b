// SPDX-License-Identifier: BSD-3-Clause
// The pose refiner over a turn: it finds a constant hand-eye error under
// per-frame pose noise, fuses every frame at the true pose within the
// registration's precision, and rejects (and counts) frames it cannot trust.
#include "graspfill/refine/pose_refiner.hpp"

#include <gtest/gtest.h>

#include <random>

#include "refine_fixtures.hpp"

namespace graspfill::refine {
namespace {

using graspfill::testing::AngleDeg;
using graspfill::testing::CameraError;
using graspfill::testing::ClawOffsetM;
using graspfill::testing::RenderFrame;
using graspfill::testing::TrueT_C_G;

class PoseRefinerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const TriangleMesh claw = graspfill::testing::PosedClaw();
    raycaster_.AddMesh(claw);
    raycaster_.Commit();
    refiner_.SetClaw(claw);
  }
  // Logged pose: hand-eye error E, then 0.5 mm / 0.2 deg noise in G.
  Eigen::Isometry3d Logged(const Eigen::Isometry3d& truth, std::mt19937* rng) const {
    std::normal_distribution<double> n(0.0, 1.0);
    const Eigen::Vector3d t(n(*rng), n(*rng), n(*rng));
    const Eigen::Vector3d w(n(*rng), n(*rng), n(*rng));
    Eigen::Isometry3d N = Eigen::Isometry3d::Identity();
    N.translation() = t * (0.0005 / std::sqrt(3.0));
    const double angle = w.norm() * (0.2 / std::sqrt(3.0)) * M_PI / 180.0;
    N.linear() = Eigen::AngleAxisd(angle, w.normalized()).toRotationMatrix();
    return E_ * truth * N;
  }
  const Eigen::Isometry3d E_ =
      CameraError(3.0, Eigen::Vector3d(-1, 0.4, 1), 1.0, Eigen::Vector3d(1, 0.2, 0.5));
  Raycaster raycaster_;
  // The registration's own precision: no deadband (the default's is below).
  PoseRefiner refiner_{[] {
    RefineConfig exact;
    exact.min_correction_m = 0.0;
    exact.min_correction_deg = 0.0;
    return exact;
  }()};
};

TEST_F(PoseRefinerTest, FindsTheHandEyeErrorAndFusesAtTheTruePose) {
  std::mt19937 rng(5);
  double worst_logged = 0.0, worst_refined = 0.0;
  for (int k = 0; k < 14; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(0.45 * k);
    const DepthFrame frame = RenderFrame(raycaster_, truth, 0.001, 100 + k);
    const Eigen::Isometry3d logged = Logged(truth, &rng);
    Eigen::Isometry3d refined;
    ASSERT_EQ(refiner_.Refine(frame, logged, &refined), RefineOutcome::kRefined) << "frame " << k;
    worst_logged = std::max(worst_logged, ClawOffsetM(logged, truth));
    worst_refined = std::max(worst_refined, ClawOffsetM(refined, truth));
  }
  EXPECT_GT(worst_logged, 0.006);    // the error is there...
  EXPECT_LT(worst_refined, 0.0005);  // ...and gone
  // The hand-eye correction undoes E at the claw.
  const Eigen::Isometry3d H = refiner_.HandEyeCorrection();
  const Eigen::Isometry3d truth = TrueT_C_G(0.0);
  EXPECT_LT(ClawOffsetM(H * E_ * truth, truth), 0.0005);
  EXPECT_LT(AngleDeg(H * E_, Eigen::Isometry3d::Identity()), 0.3);
  EXPECT_EQ(refiner_.stats().frames_refined, 14);
  EXPECT_EQ(refiner_.stats().rejected(), 0);
}

TEST_F(PoseRefinerTest, RejectsAndCountsFramesItCannotTrust) {
  std::mt19937 rng(9);
  for (int k = 0; k < 6; ++k) {  // a known hand-eye correction first
    const Eigen::Isometry3d truth = TrueT_C_G(0.5 * k);
    Eigen::Isometry3d refined;
    ASSERT_EQ(refiner_.Refine(RenderFrame(raycaster_, truth, 0.001, k), Logged(truth, &rng), &refined),
              RefineOutcome::kRefined)
        << "frame " << k << ": " << RegistrationStatusName(refiner_.last_registration().status) << " after "
        << refiner_.last_registration().iterations << " iterations, rms "
        << refiner_.last_registration().rms_m << " m, " << refiner_.last_registration().matches << " matches";
  }
  const Eigen::Isometry3d truth = TrueT_C_G(3.2);
  const Eigen::Isometry3d logged = Logged(truth, &rng);
  Eigen::Isometry3d refined = Eigen::Isometry3d::Identity();
  // No claw in view.
  EXPECT_EQ(refiner_.Refine(RenderFrame(raycaster_, truth, 0.001, 50, false), logged, &refined),
            RefineOutcome::kClawNotSeen);
  // Almost no valid depth.
  DepthFrame sparse = RenderFrame(raycaster_, truth, 0.001, 51);
  for (size_t i = 0; i < sparse.depth_m.size(); ++i) {
    if (i % 97 != 0) sparse.depth_m[i] = 0.0f;
  }
  EXPECT_EQ(refiner_.Refine(sparse, logged, &refined), RefineOutcome::kClawNotSeen);
  // A logged pose that jumped by 10 cm.
  Eigen::Isometry3d jumped = logged;
  jumped.translation().y() += 0.10;
  EXPECT_NE(refiner_.Refine(RenderFrame(raycaster_, truth, 0.001, 52), jumped, &refined),
            RefineOutcome::kRefined);
  EXPECT_TRUE(refined.isApprox(Eigen::Isometry3d::Identity()));  // untouched
  EXPECT_EQ(refiner_.stats().rejected(), 3);
  EXPECT_EQ(refiner_.stats().rejected_claw_not_seen + refiner_.stats().rejected_jump +
                refiner_.stats().rejected_not_converged,
            3);
  // The estimate survived them: the next good frame refines.
  EXPECT_EQ(refiner_.Refine(RenderFrame(raycaster_, truth, 0.001, 53), logged, &refined),
            RefineOutcome::kRefined);
  EXPECT_LT(ClawOffsetM(refined, truth), 0.0005);
}

// With the default deadband, a frame whose registration lands within
// min_correction of the prediction is fused at the prediction itself (the
// registration's jitter is not fused), the others at their registration.
TEST_F(PoseRefinerTest, TheDefaultDeadbandFusesSmallCorrectionsAtThePrediction) {
  PoseRefiner refiner;  // the defaults
  ASSERT_TRUE(refiner.config().enabled);
  ASSERT_GT(refiner.config().min_correction_m, 0.0);
  refiner.SetClaw(graspfill::testing::PosedClaw());
  std::mt19937 rng(5);
  int at_prediction = 0;
  double worst = 0.0;
  for (int k = 0; k < 14; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(0.45 * k);
    const Eigen::Isometry3d logged = Logged(truth, &rng);
    const Eigen::Isometry3d prediction = refiner.HandEyeCorrection() * logged;
    const int64_t before = refiner.stats().frames_at_prediction;
    Eigen::Isometry3d refined;
    const RefineOutcome outcome =
        refiner.Refine(RenderFrame(raycaster_, truth, 0.001, 100 + k), logged, &refined);
    ASSERT_TRUE(outcome == RefineOutcome::kRefined || outcome == RefineOutcome::kAtPrediction)
        << "frame " << k << ": " << RefineOutcomeName(outcome);
    const bool held = outcome == RefineOutcome::kAtPrediction;
    EXPECT_EQ(held, refiner.stats().frames_at_prediction > before) << "frame " << k;
    at_prediction += held;
    if (held) {
      EXPECT_TRUE(refined.isApprox(prediction, 1e-12)) << "frame " << k;
    } else {
      EXPECT_TRUE(refined.isApprox(refiner.last_registration().T_C_G, 1e-12)) << "frame " << k;
    }
    worst = std::max(worst, ClawOffsetM(refined, truth));
  }
  EXPECT_GT(at_prediction, 0);
  EXPECT_LT(at_prediction, 14);  // 0.5 mm / 0.2 deg of noise: some frames move more
  // Within the deadband of a registration that is within 0.5 mm.
  EXPECT_LT(worst, 0.0005 + refiner.config().min_correction_m);
}

// A depth 1% long, divided by the applied factor as the pipeline does:
// after kDepthScaleMinFrames frames the factor is found (within 0.2%) and
// applied, the hand-eye estimate starts anew at that moment, and once it
// is known again it is the injected error's, not the scale's shift along
// the ray. With apply_depth_scale false the factor is only reported.
TEST_F(PoseRefinerTest, FindsTheDepthScaleAndKeepsItOutOfTheHandEye) {
  RefineConfig report_only;
  report_only.apply_depth_scale = false;
  PoseRefiner reporter(report_only);
  reporter.SetClaw(graspfill::testing::PosedClaw());
  std::mt19937 rng(9);
  int changed_at = -1;
  for (int k = 0; k < kDepthScaleMinFrames + 12; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(0.3 * k);
    const DepthFrame exact = RenderFrame(raycaster_, truth, 0.001, 200 + k);
    const Eigen::Isometry3d logged = Logged(truth, &rng);
    for (PoseRefiner* refiner : {&refiner_, &reporter}) {
      DepthFrame frame = exact;
      const float divide = static_cast<float>(1.01 / refiner->depth_scale().applied);
      for (float& z : frame.depth_m) z *= divide;
      Eigen::Isometry3d refined;
      ASSERT_TRUE(Fuses(refiner->Refine(frame, logged, &refined))) << "frame " << k;
      const bool changed = refiner->CalibrateDepthScale();
      if (refiner == &reporter) {
        EXPECT_FALSE(changed);
        continue;
      }
      if (changed) {
        EXPECT_EQ(changed_at, -1) << "applied twice";
        changed_at = k;
        EXPECT_EQ(refiner->hand_eye_samples(), 0);
      }
    }
  }
  EXPECT_EQ(changed_at, kDepthScaleMinFrames - 1);
  EXPECT_NEAR(refiner_.depth_scale().applied, 1.01, 0.002);
  EXPECT_NEAR(reporter.depth_scale().factor, 1.01, 0.002);
  EXPECT_EQ(reporter.depth_scale().applied, 1.0);
  // H undoes E at the claw once the scale is out of the depth; the
  // reporter's H also carries the scale's 5.5 mm along the ray.
  const Eigen::Vector3d centre = refiner_.claw_centre_C();
  const double left_m = ((refiner_.HandEyeCorrection() * E_) * centre - centre).norm();
  const double reporter_left_m = ((reporter.HandEyeCorrection() * E_) * centre - centre).norm();
  EXPECT_LT(left_m, 0.001);
  EXPECT_GT(reporter_left_m, 0.004);
}

TEST(PoseRefiner, OffPassesTheLoggedPoseThrough) {
  RefineConfig off;
  off.enabled = false;
  PoseRefiner refiner(off);
  DepthFrame frame;
  Eigen::Isometry3d logged = TrueT_C_G(0.3), out;
  EXPECT_EQ(refiner.Refine(frame, logged, &out), RefineOutcome::kOff);
  EXPECT_TRUE(out.isApprox(logged));
  RefineConfig bad;
  bad.hand_eye_window = 2;  // below hand_eye_min_frames
  EXPECT_THROW(PoseRefiner{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::refine
