// SPDX-License-Identifier: BSD-3-Clause
// The frame path allocates nothing it could reuse: once the volume has the
// units a frame touches and the visibility record holds all its key
// frames, a frame goes through the whole pipeline (the pose, its
// refinement, the crop, the claw's cut-out, the integration, the key-frame
// test) without one heap allocation. New units and new key frames allocate
// what they keep. (Open3D's own ScalableTSDFVolume::Integrate allocated on
// every frame: with it, this test fails.)
#include <gtest/gtest.h>

#include <vector>

#include "../allocation_count.hpp"
#include "sphere_scene.hpp"

namespace graspfill {
namespace {

class PipelineAllocations : public PipelineTest {};

TEST_F(PipelineAllocations, AFrameOnceUnitsAndKeyFramesExistAllocatesNothing) {
  // A turn and a quarter of the gripper (1.5 rad/s at 30 Hz), rendered
  // first: the allocations counted are the pipeline's alone.
  constexpr int kFrames = 160, kCounted = 30;
  std::vector<DepthFrame> frames;
  std::vector<std::vector<GripperState>> states(kFrames);
  int64_t next_state = 3700;
  for (int i = 0; i < kFrames; ++i) {
    const int64_t t = 100000 + i * 33333;
    for (; next_state <= t; next_state += 10000) states[i].push_back(State(next_state));
    frames.push_back(Render(raycaster_, T_C_G_at(t * 1e-6), t));
  }
  Pipeline pipeline(PipelineConfig{}, Claw());
  int key_frame_allocations = 0, counted_integrated = 0;
  for (int i = 0; i < kFrames; ++i) {
    const size_t key_frames = pipeline.visibility().size();
    const int64_t integrated = pipeline.stats().frames_integrated;
    const long before = testing::Allocations();
    // A frame is integrated when the state after it arrives: one cycle is
    // the states up to a frame, then the frame.
    for (const GripperState& s : states[i]) pipeline.AddGripperState(s);
    pipeline.AddDepthFrame(frames[i]);
    const long allocations = testing::Allocations() - before;
    if (pipeline.visibility().size() > key_frames && allocations > 0) ++key_frame_allocations;
    if (i < kFrames - kCounted) continue;
    EXPECT_EQ(allocations, 0) << "frame " << i;
    counted_integrated += static_cast<int>(pipeline.stats().frames_integrated - integrated);
  }
  // The frames counted were fused, after the record had filled up.
  EXPECT_EQ(counted_integrated, kCounted);
  EXPECT_EQ(pipeline.visibility().size(), static_cast<size_t>(PipelineConfig{}.visibility.max_key_frames));
  // What a new key frame keeps is allocated and counted: the count sees
  // the pipeline's allocations at all.
  EXPECT_GT(key_frame_allocations, 10);
}

}  // namespace
}  // namespace graspfill
