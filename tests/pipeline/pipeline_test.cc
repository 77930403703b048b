// SPDX-License-Identifier: BSD-3-Clause
// The module end to end on an analytic scene (sphere_scene.hpp).
#include "graspfill/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "graspfill/fusion/tsdf_fusion.hpp"
#include "sphere_scene.hpp"

namespace graspfill {
namespace {

TEST_F(PipelineTest, CloudLiesOnTheSphereWithoutTheClaw) {
  Pipeline pipeline(PipelineConfig{}, Claw());
  Feed(&pipeline, 60);
  EXPECT_EQ(pipeline.stats().frames_integrated, 60);
  EXPECT_EQ(pipeline.stats().claw_rebuilds, 1);
  EXPECT_EQ(pipeline.stats().claw_rebuild.count, 1);  // the rebuild timed, on the frame that made it
  EXPECT_GT(pipeline.stats().claw_rebuild.total_ms, 0.0);
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
  EXPECT_GE(all_at_prediction, 3u);       // 40 frames at 1.5 rad/s: 115 deg, a key frame every 12
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

// The frame the pipeline last fused, as it fused it: integrating those
// frames at their poses into another volume of the same settings gives the
// pipeline's own cloud, point for point (what `graspfill bench` times
// Open3D on). The raw frames would not: they hold the claw.
TEST_F(PipelineTest, LastFusedFrameRebuildsTheSameVolume) {
  PipelineConfig config;
  Pipeline pipeline(config, Claw());
  fusion::TsdfFusion same_frames(config.tsdf);
  int64_t seen = 0, batched = 0, claw_pixels_left = 0;
  Feed(&pipeline, 30, CameraIntrinsics{}, [&] {
    const int64_t fused = pipeline.stats().frames_integrated;
    if (fused == seen) return;
    batched += fused - seen - 1;
    seen = fused;
    const DepthFrame& frame = pipeline.last_fused_frame();
    const Eigen::Isometry3d T_C_G = pipeline.last_fused_T_C_V();
    for (size_t i = 0; i < frame.depth_m.size(); ++i) {
      const float z = frame.depth_m[i];
      if (!(z > 0.0f)) continue;
      const int u = static_cast<int>(i % static_cast<size_t>(frame.intrinsics.width));
      const int v = static_cast<int>(i / static_cast<size_t>(frame.intrinsics.width));
      const Eigen::Vector3d p_C((u - frame.intrinsics.cx) * z / frame.intrinsics.fx,
                                (v - frame.intrinsics.cy) * z / frame.intrinsics.fy, z);
      const Eigen::Vector3d p_G = T_C_G.inverse() * p_C;
      claw_pixels_left += std::abs((p_G - kCentreG).norm() - kRadiusM) > 0.002;
    }
    same_frames.Integrate(frame, T_C_G);
  });
  ASSERT_EQ(batched, 0) << "the scene fuses one frame per call";
  EXPECT_EQ(seen, 30);
  EXPECT_EQ(claw_pixels_left, 0);  // cropped and masked: the sphere alone
  ObjectCloud own, rebuilt;
  pipeline.fusion().ExtractCloudUncached(&own);
  same_frames.ExtractCloudUncached(&rebuilt);
  ASSERT_GT(own.size(), 2000u);
  ASSERT_EQ(rebuilt.size(), own.size());
  for (size_t i = 0; i < own.size(); ++i) ASSERT_EQ(rebuilt.points_G[i], own.points_G[i]) << i;
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

// Every skipped frame comes back once, with its reason, from the call that
// decided it; the stats count it under that reason.
TEST_F(PipelineTest, EverySkippedFrameComesBackWithItsReason) {
  PipelineConfig config;
  config.max_pending_frames = 1;
  Pipeline pipeline(config, Claw());
  const DepthFrame frame = Render(raycaster_, T_C_G_at(0.1), 100000);
  auto decided_once = [&](int64_t utime, FrameSkipReason skip) {
    ASSERT_EQ(pipeline.decided().size(), 1u);
    EXPECT_EQ(pipeline.decided()[0].utime, utime);
    EXPECT_EQ(pipeline.decided()[0].skip, skip) << FrameSkipReasonName(pipeline.decided()[0].skip);
  };
  DepthFrame bad = frame;
  bad.depth_m.resize(100);
  EXPECT_EQ(pipeline.AddDepthFrame(bad), FrameOutcome::kBadFrame);
  decided_once(100000, FrameSkipReason::kBadFrame);

  // Waiting, then dropped for the next one (one pending slot).
  EXPECT_EQ(pipeline.AddDepthFrame(frame), FrameOutcome::kPending);
  EXPECT_TRUE(pipeline.decided().empty());
  DepthFrame later = frame;
  later.utime = 110000;
  EXPECT_EQ(pipeline.AddDepthFrame(later), FrameOutcome::kPending);
  decided_once(100000, FrameSkipReason::kPendingFull);

  // Decided by a state: two states 150 ms apart around it.
  pipeline.AddGripperState(State(50000));
  EXPECT_TRUE(pipeline.decided().empty());
  pipeline.AddGripperState(State(200000));
  decided_once(110000, FrameSkipReason::kPoseGap);

  DepthFrame early = frame;
  early.utime = 20000;  // older than every state
  EXPECT_EQ(pipeline.AddDepthFrame(early), FrameOutcome::kSkippedNoPose);
  decided_once(20000, FrameSkipReason::kNoPoseBefore);

  DepthFrame last = frame;
  last.utime = 400000;  // never bracketed
  EXPECT_EQ(pipeline.AddDepthFrame(last), FrameOutcome::kPending);
  pipeline.Flush();
  decided_once(400000, FrameSkipReason::kNoPoseAfter);

  const FrameSkipCounts& skipped = pipeline.stats().skipped;
  EXPECT_EQ(skipped.total(), 5);
  for (FrameSkipReason r :
       {FrameSkipReason::kBadFrame, FrameSkipReason::kPendingFull, FrameSkipReason::kPoseGap,
        FrameSkipReason::kNoPoseBefore, FrameSkipReason::kNoPoseAfter}) {
    EXPECT_EQ(skipped[r], 1) << FrameSkipReasonName(r);
  }
  EXPECT_EQ(pipeline.stats().frames_skipped_no_pose, 3);
  EXPECT_EQ(pipeline.stats().frames_dropped, 1);
}

TEST_F(PipelineTest, FramesTheRefinementRejectsComeBackWithItsReason) {
  Pipeline pipeline(PipelineConfig{}, Claw());
  Feed(&pipeline, 6);
  ASSERT_EQ(pipeline.stats().frames_integrated, 6);
  // A frame with no depth at all: the claw is not seen.
  const int64_t t = 100000 + 6 * 33333;
  DepthFrame empty = Render(raycaster_, T_C_G_at(t * 1e-6), t);
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), 0.0f);
  pipeline.AddGripperState(State(t + 10000));
  EXPECT_EQ(pipeline.AddDepthFrame(empty), FrameOutcome::kSkippedRefine);
  ASSERT_EQ(pipeline.decided().size(), 1u);
  EXPECT_EQ(pipeline.decided()[0].skip, FrameSkipReason::kClawNotSeen);
  // A frame rendered 1 cm off the state's pose: a correction that jumps.
  const int64_t t2 = t + 33333;
  Eigen::Isometry3d shifted = T_C_G_at(t2 * 1e-6);
  shifted.translation() += Eigen::Vector3d(0.01, 0.0, 0.0);
  pipeline.AddGripperState(State(t2 + 10000));
  EXPECT_EQ(pipeline.AddDepthFrame(Render(raycaster_, shifted, t2)), FrameOutcome::kSkippedRefine);
  ASSERT_EQ(pipeline.decided().size(), 1u);
  EXPECT_EQ(pipeline.decided()[0].skip, FrameSkipReason::kRefineJump)
      << FrameSkipReasonName(pipeline.decided()[0].skip);
  EXPECT_EQ(pipeline.stats().skipped[FrameSkipReason::kClawNotSeen], 1);
  EXPECT_EQ(pipeline.stats().skipped.total(), 2);
}

TEST_F(PipelineTest, FramesTheTrackingRejectsComeBackWithItsReason) {
  PipelineConfig config;
  config.track_object.enabled = true;
  config.track_object.warmup_frames = 4;
  Pipeline pipeline(config, Claw());
  Feed(&pipeline, 6);
  ASSERT_EQ(pipeline.stats().frames_integrated, 6);
  ASSERT_TRUE(pipeline.tracker().has_model());
  // The claw alone, no object: refinement sees the claw, tracking no object.
  const int64_t t = 100000 + 6 * 33333;
  pipeline.AddGripperState(State(t + 10000));
  EXPECT_EQ(pipeline.AddDepthFrame(Render(raycaster_, T_C_G_at(t * 1e-6), t, {}, 0.0)),
            FrameOutcome::kSkippedTracking);
  ASSERT_EQ(pipeline.decided().size(), 1u);
  EXPECT_EQ(pipeline.decided()[0].skip, FrameSkipReason::kTrackTooFewPoints)
      << FrameSkipReasonName(pipeline.decided()[0].skip);
  EXPECT_EQ(pipeline.stats().skipped[FrameSkipReason::kTrackTooFewPoints], 1);
}

TEST(FrameSkipReason, NamesAreDistinctAndReadBack) {
  for (size_t i = 0; i < kNumFrameSkipReasons; ++i) {
    const auto reason = static_cast<FrameSkipReason>(i);
    const std::string name = FrameSkipReasonName(reason);
    EXPECT_NE(name, "unknown");
    EXPECT_EQ(FrameSkipReasonFromName(name), reason) << name;
  }
  EXPECT_FALSE(FrameSkipReasonFromName("unknown").has_value());
  FrameSkipCounts counts;
  counts.Count(FrameSkipReason::kPoseGap, 3);
  counts.Count(FrameSkipReason::kClawNotSeen, 2);
  EXPECT_EQ(FrameSkipText(counts), "pose_gap 3, claw_not_seen 2");
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
