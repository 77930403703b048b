// SPDX-License-Identifier: BSD-3-Clause
// The claw registration recovers a known pose error from noisy depth, and
// says so when the claw is not in view; Open3D's point-to-plane ICP on the
// same frames, beside it.
#include "graspfill/refine/claw_registration.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/RobustKernel.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "graspfill/core/percentile.hpp"
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

// The issue's choice, "Open3D's registration or your own on Eigen, whichever
// measures better", measured: the same four frames and the same ~10 mm
// start, Open3D's RegistrationICP (point-to-plane, Huber kernel at our
// 1.5 mm, its KD-tree of the model built per call as its API does) given
// the depth points ours considers (those near the predicted claw, an even
// subsample of about 1500) and our gate schedule (25 mm shrinking by 0.6
// to 4 mm, then to convergence there). Both must land within 0.2 mm and
// 0.25 deg of the truth on every frame (1 mm depth noise); the offsets and
// the times are printed (docs/measurements/2026-12-03-imperfect-robots.md:
// the same accuracy, ours ~40x faster, its lookup table built once per claw
// where Open3D builds a KD-tree per call).
TEST_F(ClawRegistrationTest, MatchesOpen3DsICPOnTheSameFrames) {
  namespace reg = open3d::pipelines::registration;
  open3d::geometry::PointCloud model;
  for (size_t i = 0; i < registration_.model_points_G().size(); ++i) {
    model.points_.push_back(registration_.model_points_G()[i].cast<double>());
    model.normals_.push_back(registration_.model_normals_G()[i].cast<double>());
  }
  Eigen::AlignedBox3d box_G;
  for (const Eigen::Vector3d& p : model.points_) box_G.extend(p);
  const double gate0 = 0.025;
  box_G.min().array() -= gate0;
  box_G.max().array() += gate0;
  const double thetas[] = {0.0, 0.7, 1.9, 3.0};
  double ours_ms = 0.0, open3d_ms = 0.0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(thetas[k]);
    const DepthFrame frame = RenderFrame(raycaster_, truth, 0.001, 17 + k);
    const Eigen::Isometry3d initial =
        CameraError(3.0, Eigen::Vector3d(1, -2, 0.5), 1.0, Eigen::Vector3d(0.3, 1, -0.2)) * truth;
    auto start = std::chrono::steady_clock::now();
    const RegistrationResult ours = registration_.Register(frame, initial, gate0);
    ours_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(ours.status, RegistrationStatus::kConverged);

    // The depth points near the predicted claw, in G at the initial pose.
    const CameraIntrinsics& K = frame.intrinsics;
    const Eigen::Isometry3d T_G_C = initial.inverse();
    open3d::geometry::PointCloud source;
    for (int v = 0; v < K.height; ++v) {
      for (int u = 0; u < K.width; ++u) {
        const double z = frame.at(u, v);
        if (!(z > 0.0)) continue;
        const Eigen::Vector3d p_G = T_G_C * Eigen::Vector3d((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
        if (box_G.contains(p_G)) source.points_.push_back(p_G);
      }
    }
    ASSERT_GT(source.points_.size(), 1500u);
    source = *source.UniformDownSample(source.points_.size() / 1500);
    start = std::chrono::steady_clock::now();
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    const auto estimation =
        reg::TransformationEstimationPointToPlane(std::make_shared<reg::HuberLoss>(0.0015));
    for (double gate = gate0; gate > 0.004; gate *= 0.6) {
      T = reg::RegistrationICP(source, model, gate, T, estimation, reg::ICPConvergenceCriteria(1e-9, 1e-9, 1))
              .transformation_;
    }
    T = reg::RegistrationICP(source, model, 0.004, T, estimation, reg::ICPConvergenceCriteria(1e-9, 1e-9, 30))
            .transformation_;
    open3d_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    // T moves the points (G at the initial pose) onto the model: T_G_C = T * initial^-1.
    const Eigen::Isometry3d open3d_T_C_G = initial * Eigen::Isometry3d(T).inverse();
    const double ours_mm = 1000 * ClawOffsetM(ours.T_C_G, truth);
    const double open3d_mm = 1000 * ClawOffsetM(open3d_T_C_G, truth);
    std::printf("theta %.1f, %zu points: ours %.3f mm / %.3f deg off, Open3D's ICP %.3f mm / %.3f deg off\n",
                thetas[k], source.points_.size(), ours_mm, AngleDeg(ours.T_C_G, truth), open3d_mm,
                AngleDeg(open3d_T_C_G, truth));
    // Both at the depth noise's floor: what decides is the time.
    EXPECT_LT(ours_mm, 0.2) << "theta " << thetas[k];
    EXPECT_LT(open3d_mm, 0.2) << "theta " << thetas[k];
    EXPECT_LT(AngleDeg(open3d_T_C_G, truth), 0.25) << "theta " << thetas[k];
  }
  std::printf("per frame: ours %.2f ms (one thread), Open3D's ICP %.2f ms (its OpenMP threads)\n",
              ours_ms / 4, open3d_ms / 4);
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

// A depth 1% long puts every point 1% farther along its ray: 5.5 mm at
// the claw, which the registration takes as a shift, and a claw 1% larger,
// which the scale estimate finds. Exact depth shows no scale. Eight views,
// the same noise with and without the error.
TEST_F(ClawRegistrationTest, FindsTheDepthScaleFromTheClawsSize) {
  std::vector<double> exact, long_by_1pc, difference;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Isometry3d truth = TrueT_C_G(0.8 * k);
    const DepthFrame frame = RenderFrame(raycaster_, truth, 0.001, 40 + k);
    double error[2] = {0.0, 0.0};
    for (int i = 0; i < 2; ++i) {
      DepthFrame scaled = frame;
      for (float& z : scaled.depth_m) z *= i == 0 ? 1.0f : 1.01f;
      const RegistrationResult r = registration_.Register(scaled, truth, 0.025);
      ASSERT_EQ(r.status, RegistrationStatus::kConverged) << "view " << k;
      DepthScaleSample sample;
      ASSERT_TRUE(registration_.EstimateDepthScale(r, &sample)) << "view " << k;
      EXPECT_GT(sample.stderr_, 0.0);
      EXPECT_LT(sample.stderr_, 0.003);
      EXPECT_GT(sample.matches, 300);
      error[i] = sample.error;
    }
    exact.push_back(error[0]);
    long_by_1pc.push_back(error[1]);
    difference.push_back(error[1] - error[0]);
  }
  std::printf("depth scale error, median of 8 views: exact %+.4f%%, 1%% long %+.4f%%, difference %+.4f%%\n",
              100.0 * Percentile(exact, 50.0), 100.0 * Percentile(long_by_1pc, 50.0),
              100.0 * Percentile(difference, 50.0));
  // One frame's estimate falls a few % short of the error (0.94% of 1%
  // here); the session's, estimated again on the divided depth, closes the
  // gap (pose_refiner_test, e2e_refine_test).
  EXPECT_NEAR(Percentile(exact, 50.0), 0.0, 0.001);
  EXPECT_NEAR(Percentile(long_by_1pc, 50.0), 0.01, 0.0015);
  EXPECT_NEAR(Percentile(difference, 50.0), 0.01, 0.001);
  // Nothing to estimate from a registration that did not converge.
  RegistrationResult failed;
  failed.status = RegistrationStatus::kNotConverged;
  DepthScaleSample sample;
  EXPECT_FALSE(registration_.EstimateDepthScale(failed, &sample));
}

TEST(ClawRegistrationConfig, BadValuesAreRejected) {
  EXPECT_NO_THROW(ClawRegistrationConfig{}.Validate());
  ClawRegistrationConfig bad;
  bad.final_gate_m = 0.01;  // beyond the fine band
  EXPECT_THROW(ClawRegistration{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::refine
