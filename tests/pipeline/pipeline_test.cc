// SPDX-License-Identifier: BSD-3-Clause
// The module end to end on an analytic scene: a sphere held by the
// three-finger claw, seen by a fixed camera while the gripper turns.
#include "graspfill/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "graspfill/core/raycaster.hpp"

namespace graspfill {
namespace {

constexpr double kRadiusM = 0.035;
const Eigen::Vector3d kCentreG(0.0, 0.0, 0.045);  // top 1 cm below the palm
constexpr double kOpeningM = 0.0355;              // fingers touch the equator... roughly

claw::ClawModel Claw() { return claw::ClawModel::ThreeFinger(); }

// Gripper approach axis pointing down-ish, turning about its z over time.
Eigen::Isometry3d T_C_G_at(double t_s) {
  Eigen::Isometry3d T_W_G = Eigen::Isometry3d::Identity();
  // World: camera looks along +x_W, z_W up. The gripper's z points down.
  T_W_G.linear() = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(1.5 * t_s, Eigen::Vector3d::UnitZ())).toRotationMatrix();
  T_W_G.translation() = Eigen::Vector3d(0.55, 0.0, 0.20);
  // Camera 15 cm below the object centre, looking at it (slightly upward).
  const Eigen::Vector3d eye(0.0, 0.0, 0.0);
  const Eigen::Vector3d target = T_W_G * kCentreG;
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  T_W_C.linear().col(0) = x;
  T_W_C.linear().col(1) = z.cross(x);
  T_W_C.linear().col(2) = z;
  T_W_C.translation() = eye;
  return T_W_C.inverse() * T_W_G;
}

// Exact depth of the sphere + claw (claw by Embree, sphere analytically).
DepthFrame Render(const Raycaster& claw_G, const Eigen::Isometry3d& T_C_G, int64_t utime,
                  const CameraIntrinsics& intrinsics = CameraIntrinsics{}) {
  DepthFrame f;
  f.utime = utime;
  f.intrinsics = intrinsics;
  const CameraIntrinsics& K = f.intrinsics;
  f.depth_m.assign(K.width * K.height, 0.0f);
  const Eigen::Isometry3d T_G_C = T_C_G.inverse();
  const Eigen::Vector3d c_C = T_C_G * kCentreG;
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      double z = 1.5;  // background wall, outside the workspace
      const double a = ray.squaredNorm(), b = -2.0 * ray.dot(c_C);
      const double disc = b * b - 4 * a * (c_C.squaredNorm() - kRadiusM * kRadiusM);
      if (disc >= 0) z = std::min(z, (-b - std::sqrt(disc)) / (2 * a));
      const Eigen::Vector3d dir_G = (T_G_C.linear() * ray.normalized());
      const RayHit hit = claw_G.Cast(T_G_C.translation().cast<float>(), dir_G.cast<float>());
      if (hit.hit()) z = std::min(z, hit.t / std::sqrt(a));  // t along the unit ray
      f.depth_m[v * K.width + u] = static_cast<float>(z);
    }
  }
  return f;
}

GripperState State(int64_t utime) {
  GripperState s;
  s.utime = utime;
  s.T_C_G = T_C_G_at(utime * 1e-6);
  s.opening_m = kOpeningM;
  return s;
}

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    raycaster_.AddMesh(Claw().Posed(kOpeningM));
    raycaster_.Commit();
  }
  // Feeds 100 Hz states (offset 3.7 ms) and 30 Hz frames in time order.
  void Feed(Pipeline* p, int num_frames, const CameraIntrinsics& K = CameraIntrinsics{}) {
    int64_t next_state = 3700;
    for (int i = 0; i < num_frames; ++i) {
      const int64_t t = 100000 + i * 33333;
      while (next_state <= t) {
        p->AddGripperState(State(next_state));
        next_state += 10000;
      }
      p->AddDepthFrame(Render(raycaster_, T_C_G_at(t * 1e-6), t, K));
    }
    p->AddGripperState(State(next_state));
    p->Flush();
  }
  Raycaster raycaster_;
};

TEST_F(PipelineTest, CloudLiesOnTheSphereWithoutTheClaw) {
  Pipeline pipeline(PipelineConfig{}, Claw());
  Feed(&pipeline, 60);
  EXPECT_EQ(pipeline.stats().frames_integrated, 60);
  EXPECT_EQ(pipeline.stats().claw_rebuilds, 1);
  const ObjectCloud cloud = pipeline.ExtractCloud();
  ASSERT_GT(cloud.size(), 2000u);
  int off_surface = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) {
    if (std::abs((p.cast<double>() - kCentreG).norm() - kRadiusM) > 0.002) ++off_surface;
  }
  // No claw left: every point is on the sphere (claw fingers are >= 0.5 mm
  // off it, their outer faces 12 mm off).
  EXPECT_LT(off_surface, static_cast<int>(0.001 * cloud.size()) + 1);
  // The top (facing the palm, z_G < centre - 0.8 r) is never seen.
  int top = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) top += p.z() < kCentreG.z() - 0.8 * kRadiusM;
  EXPECT_EQ(top, 0);
}

// A frame fused at its own registration, off the prediction, is not made
// a key frame of the visibility record (its move may be the registration's
// error); with no deadband every registration is trusted.
TEST_F(PipelineTest, FramesFusedOffThePredictionAreNoKeyFrames) {
  auto key_frames = [&](double min_correction_m, double min_correction_deg) {
    PipelineConfig config;
    config.refine.min_correction_m = min_correction_m;
    config.refine.min_correction_deg = min_correction_deg;
    Pipeline pipeline(config, Claw());
    Feed(&pipeline, 40);
    EXPECT_EQ(pipeline.stats().frames_integrated, 40);
    return pipeline.visibility().size();
  };
  const size_t all_at_prediction = key_frames(1.0, 180.0);
  EXPECT_GE(all_at_prediction, 3u);  // 40 frames at 1.5 rad/s: 115 deg, a key frame every 12
  EXPECT_EQ(key_frames(1e-9, 1e-9), 0u);  // every registration moves the pose a little
  EXPECT_GE(key_frames(0.0, 0.0) + 1, all_at_prediction);  // the same views, within a pose jitter
}

int PointsOffTheSphere(const ObjectCloud& cloud) {
  int off_surface = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) {
    if (std::abs((p.cast<double>() - kCentreG).norm() - kRadiusM) > 0.002) ++off_surface;
  }
  return off_surface;
}

// A camera with more pixels than max_fusion_pixels is fused decimated: the
// same sphere, as complete and as clean as at VGA, from a quarter of the
// pixels of 1280 x 960 frames.
TEST_F(PipelineTest, LargeFramesAreDecimatedToThePixelLimit) {
  CameraIntrinsics K;
  K.width = 1280;
  K.height = 960;
  K.fx = K.fy = 1050.0;
  K.cx = 639.5;
  K.cy = 479.5;
  PipelineConfig config;
  config.max_fusion_pixels = 640 * 480;
  Pipeline large(config, Claw());
  Feed(&large, 30, K);
  EXPECT_EQ(large.stats().frames_integrated, 30);
  EXPECT_EQ(large.stats().frames_decimated, 30);
  const ObjectCloud cloud = large.ExtractCloud();
  Pipeline vga(PipelineConfig{}, Claw());
  Feed(&vga, 30);
  EXPECT_EQ(vga.stats().frames_decimated, 0);
  const ObjectCloud reference = vga.ExtractCloud();
  ASSERT_GT(reference.size(), 2000u);
  EXPECT_NEAR(static_cast<double>(cloud.size()) / reference.size(), 1.0, 0.05);
  EXPECT_LT(PointsOffTheSphere(cloud), static_cast<int>(0.001 * cloud.size()) + 1);
  // Each key frame is kept at the decimated size, VGA's.
  ASSERT_GT(large.visibility().size(), 0u);
  ASSERT_GT(vga.visibility().size(), 0u);
  EXPECT_NEAR(static_cast<double>(large.visibility().memory_bytes()) / large.visibility().size(),
              static_cast<double>(vga.visibility().memory_bytes()) / vga.visibility().size(),
              0.01 * vga.visibility().memory_bytes() / vga.visibility().size());
}

TEST_F(PipelineTest, WithoutTheMaskTheClawLeaksIn) {
  // Counter-check that the test above can fail: a claw-free mask
  // (empty claw) keeps the fingers in the cloud.
  claw::ProceduralClawConfig tiny;
  tiny.finger_length_m = 0.0005;  // fingers too short to mask anything
  tiny.palm_radius_m = 0.001;
  PipelineConfig unrefined;  // a claw this small cannot be registered
  unrefined.refine.enabled = false;
  Pipeline pipeline(unrefined, claw::ClawModel::ThreeFinger(tiny));
  Feed(&pipeline, 20);
  const ObjectCloud cloud = pipeline.ExtractCloud();
  int off_surface = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) {
    if (std::abs((p.cast<double>() - kCentreG).norm() - kRadiusM) > 0.002) ++off_surface;
  }
  EXPECT_GT(off_surface, 100);
}

TEST_F(PipelineTest, FramesWithoutNearbyStatesAreSkippedAndCounted) {
  Pipeline pipeline(PipelineConfig{}, Claw());
  DepthFrame f = Render(raycaster_, T_C_G_at(0.1), 100000);
  EXPECT_EQ(pipeline.AddDepthFrame(f), FrameOutcome::kPending);
  pipeline.AddGripperState(State(50000));   // before the frame...
  pipeline.AddGripperState(State(200000));  // ...and 150 ms later: a gap
  EXPECT_EQ(pipeline.stats().frames_skipped_no_pose, 1);
  f.utime = 20000;  // older than every state
  EXPECT_EQ(pipeline.AddDepthFrame(f), FrameOutcome::kSkippedNoPose);
  f.utime = 400000;  // never bracketed
  EXPECT_EQ(pipeline.AddDepthFrame(f), FrameOutcome::kPending);
  pipeline.Flush();
  EXPECT_EQ(pipeline.stats().frames_skipped_no_pose, 3);
  EXPECT_EQ(pipeline.stats().frames_integrated, 0);
}

TEST_F(PipelineTest, RejectsBadFramesAndNonFiniteStates) {
  Pipeline pipeline(PipelineConfig{}, Claw());
  DepthFrame f = Render(raycaster_, T_C_G_at(0.1), 100000);
  f.depth_m.resize(100);
  std::string error;
  EXPECT_EQ(pipeline.AddDepthFrame(f, &error), FrameOutcome::kBadFrame);
  EXPECT_NE(error.find("size"), std::string::npos);
  GripperState nan_state = State(0);
  nan_state.T_C_G.linear()(0, 0) = std::nan("");
  EXPECT_FALSE(pipeline.AddGripperState(nan_state));
  EXPECT_EQ(pipeline.stats().states_rejected, 1);
  EXPECT_EQ(pipeline.stats().frames_bad, 1);
}

TEST(PipelineConfig, DefaultsAreValidAndBadValuesRejected) {
  EXPECT_NO_THROW(PipelineConfig{}.Validate());
  PipelineConfig bad;
  bad.max_pending_frames = 0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  PipelineConfig bad_box;
  bad_box.workspace.min_G.x() = 1.0;
  EXPECT_THROW(Pipeline(bad_box, Claw()), std::invalid_argument);
  PipelineConfig no_pixels;
  no_pixels.max_fusion_pixels = 0;
  EXPECT_THROW(no_pixels.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill
