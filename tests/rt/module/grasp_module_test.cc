// SPDX-License-Identifier: BSD-3-Clause
// The threaded module against the single-threaded Pipeline on the bundled
// recording: same cloud, cloud callbacks on schedule, drops accounted for.
#include "module/grasp_module.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

std::vector<SourceEvent> LoadEvents() {
  LcmLogSource::Config config;
  config.path = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";
  LcmLogSource source(config);
  std::vector<SourceEvent> events;
  SourceEvent e;
  while (source.Next(&e) == FrameResult::kOk) events.push_back(e);
  return events;
}

TEST(GraspModule, ThreadedModuleGivesThePipelinesCloud) {
  const std::vector<SourceEvent> events = LoadEvents();
  ASSERT_GT(events.size(), 10u);

  Pipeline direct(PipelineConfig{}, claw::ClawModel::ThreeFinger());
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kDepth)
      direct.AddDepthFrame(e.depth);
    else
      direct.AddGripperState(e.gripper);
  }
  direct.Flush();
  const ObjectCloud expected = direct.ExtractCloud();

  GraspModuleConfig config;
  config.frame_queue_capacity = 1000;  // no drops: compare like with like
  config.state_queue_capacity = 10000;
  config.extract_every_n_frames = 10;
  std::atomic<int> callbacks{0};
  GraspModule module(config, claw::ClawModel::ThreeFinger(),
                     [&](const ObjectCloud&, const evidence::VisibilityRecord&) { ++callbacks; });
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kDepth)
      module.PushDepthFrame(e.depth);
    else
      module.PushGripperState(e.gripper);
  }
  const ObjectCloud cloud = module.Finish();
  const GraspModuleStatus status = module.status();
  EXPECT_EQ(status.frames_dropped, 0);
  EXPECT_EQ(status.pipeline.frames_integrated, direct.stats().frames_integrated);
  EXPECT_TRUE(cloud.points_G == expected.points_G);
  // One callback per 10 fused frames, plus the final one.
  EXPECT_EQ(callbacks.load(), direct.stats().frames_integrated / 10 + 1);
  EXPECT_EQ(status.clouds_published, callbacks.load());
}

// As on a live bus: events one at a time, in time order, each handled
// before the next arrives. A depth frame then waits for the gripper state
// after it, so AddGripperState fuses it; a cloud must still come every 10
// fused frames.
TEST(GraspModule, CloudsComeEveryNFusedFramesWhenStatesFuseThem) {
  const std::vector<SourceEvent> events = LoadEvents();
  GraspModuleConfig config;
  config.extract_every_n_frames = 10;
  std::atomic<int> callbacks{0};
  GraspModule module(config, claw::ClawModel::ThreeFinger(),
                     [&](const ObjectCloud&, const evidence::VisibilityRecord&) { ++callbacks; });
  int64_t pushed = 0;
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kDepth)
      module.PushDepthFrame(e.depth);
    else
      module.PushGripperState(e.gripper);
    ++pushed;
    // Wait (no time limit) until the worker has taken this event in.
    for (;;) {
      const PipelineStats s = module.status().pipeline;
      if (s.frames_in + s.states_in >= pushed) break;
      std::this_thread::yield();
    }
  }
  module.Finish();
  const GraspModuleStatus status = module.status();
  ASSERT_GE(status.pipeline.frames_integrated, 30);
  EXPECT_EQ(callbacks.load(), status.pipeline.frames_integrated / 10 + 1);
  EXPECT_EQ(status.clouds_published, callbacks.load());
}

TEST(GraspModule, FullQueueDropsOldestFramesAndCountsThem) {
  const std::vector<SourceEvent> events = LoadEvents();
  GraspModuleConfig config;
  config.frame_queue_capacity = 1;
  config.extract_every_n_frames = 0;
  GraspModule module(config, claw::ClawModel::ThreeFinger(), nullptr);
  int64_t pushed = 0;
  // States and frames as recorded, each frame pushed 8 times in a row: the
  // producer outpaces the worker's integration by far.
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kGripperState) {
      module.PushGripperState(e.gripper);
      continue;
    }
    for (int copy = 0; copy < 8; ++copy) {
      module.PushDepthFrame(e.depth);  // never waits for the worker
      ++pushed;
    }
  }
  module.Finish();
  const GraspModuleStatus status = module.status();
  EXPECT_EQ(status.frames_in, pushed);
  // Every frame is either dropped in the queue or reaches the pipeline.
  EXPECT_EQ(status.frames_dropped + status.pipeline.frames_in, pushed);
  EXPECT_GT(status.frames_dropped, 0);
}

TEST(GraspModule, RejectsBadConfig) {
  GraspModuleConfig config;
  config.frame_queue_capacity = 0;
  EXPECT_THROW(GraspModule(config, claw::ClawModel::ThreeFinger(), nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::rt
