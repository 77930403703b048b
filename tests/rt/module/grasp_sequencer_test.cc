// SPDX-License-Identifier: BSD-3-Clause
// Grasp after grasp and clock jumps, on the bundled recording: a new
// grasp id starts an empty volume (the second grasp's model is exactly what
// a fresh pipeline makes of its events), a release stops fusion, and a
// backwards clock jump starts over instead of skipping every frame after it.
#include "module/grasp_sequencer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
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
  // The first 12 depth frames (and the states around them): enough to fuse
  // a cloud, few enough for a fast test.
  int depth = 0;
  while (source.Next(&e) == FrameResult::kOk) {
    if (e.kind == SourceEvent::Kind::kSession) continue;
    if (e.kind == SourceEvent::Kind::kDepth && ++depth > 12) break;
    events.push_back(e);
  }
  return events;
}

// The events with their times moved by `shift_us` and their states given
// grasp id `grasp_id`.
std::vector<SourceEvent> Shifted(std::vector<SourceEvent> events, int64_t shift_us, int64_t grasp_id) {
  for (SourceEvent& e : events) {
    e.depth.utime += shift_us;
    e.gripper.utime += shift_us;
    e.gripper.grasp_id = grasp_id;
  }
  return events;
}

template <typename Target>
void Feed(const std::vector<SourceEvent>& events, Target* target) {
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kDepth)
      target->AddDepthFrame(e.depth);
    else
      target->AddGripperState(e.gripper);
  }
}

ObjectCloud FreshPipelineCloud(const std::vector<SourceEvent>& events) {
  Pipeline pipeline(PipelineConfig{}, claw::ClawModel::ThreeFinger());
  Feed(events, &pipeline);
  pipeline.Flush();
  return pipeline.ExtractCloud();
}

TEST(GraspSequencer, RecordingsWithoutGraspIdsAreOneGrasp) {
  const std::vector<SourceEvent> events = LoadEvents();
  ASSERT_GT(events.size(), 10u);
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kGripperState) {
      ASSERT_EQ(e.gripper.grasp_id, 0);  // v1 layout
    }
  }
  int finals = 0;
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {},
                           [&](const ObjectCloud& c, const evidence::VisibilityRecord&) {
                             EXPECT_TRUE(c.is_final);
                             ++finals;
                           });
  Feed(events, &sequencer);
  const ObjectCloud cloud = sequencer.Finish();
  EXPECT_EQ(finals, 1);
  EXPECT_TRUE(cloud.points_G == FreshPipelineCloud(events).points_G);
  EXPECT_EQ(sequencer.counters().grasps_completed, 1);
  EXPECT_EQ(sequencer.counters().clock_jumps, 0);
}

TEST(GraspSequencer, ANewGraspIdEndsTheGraspAndStartsAnEmptyVolume) {
  const std::vector<SourceEvent> base = LoadEvents();
  const std::vector<SourceEvent> first = Shifted(base, 0, 1);
  const std::vector<SourceEvent> second = Shifted(base, 10'000'000, 2);
  std::vector<ObjectCloud> finals;
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {},
                           [&](const ObjectCloud& c, const evidence::VisibilityRecord& seen) {
                             EXPECT_FALSE(seen.empty());
                             finals.push_back(c);
                           });
  Feed(first, &sequencer);
  EXPECT_TRUE(finals.empty());
  Feed(second, &sequencer);
  ASSERT_EQ(finals.size(), 1u);  // grasp 1 ended at grasp 2's first state
  EXPECT_EQ(finals[0].grasp_id, 1);
  EXPECT_TRUE(finals[0].is_final);
  const ObjectCloud last = sequencer.Finish();
  ASSERT_EQ(finals.size(), 2u);
  EXPECT_EQ(last.grasp_id, 2);
  // Nothing of grasp 1 in grasp 2: its model is a fresh pipeline's (the
  // events of both grasps are the same but for their time, so one fresh
  // pipeline serves for both).
  Pipeline one(PipelineConfig{}, claw::ClawModel::ThreeFinger());
  Feed(second, &one);
  one.Flush();
  const ObjectCloud fresh = one.ExtractCloud();
  EXPECT_TRUE(last.points_G == fresh.points_G);
  EXPECT_TRUE(finals[0].points_G == fresh.points_G);
  const SessionCounters c = sequencer.counters();
  EXPECT_EQ(c.grasps_started, 2);
  EXPECT_EQ(c.grasps_completed, 2);
  EXPECT_EQ(c.frames_fused, 2 * one.stats().frames_integrated);  // summed over grasps
  EXPECT_EQ(c.frames_in, 2 * one.stats().frames_in);
}

TEST(GraspSequencer, AReleaseStopsFusionUntilTheNextGrasp) {
  const std::vector<SourceEvent> base = LoadEvents();
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {}, nullptr);
  Feed(Shifted(base, 0, 1), &sequencer);
  const int64_t fused_in_grasp = sequencer.counters().frames_fused;
  ASSERT_GT(fused_in_grasp, 8);
  Feed(Shifted(base, 10'000'000, 0), &sequencer);  // released: states with id 0
  const SessionCounters c = sequencer.counters();
  EXPECT_FALSE(c.holding);
  EXPECT_EQ(c.grasps_completed, 1);
  EXPECT_EQ(c.frames_fused, fused_in_grasp);
  EXPECT_GT(c.frames_released, 8);
  EXPECT_EQ(c.skipped[FrameSkipReason::kClawEmpty], c.frames_released);
  EXPECT_EQ(sequencer.stats().skipped[FrameSkipReason::kClawEmpty], c.frames_released);
}

TEST(GraspSequencer, ABackwardsClockJumpStartsOverInsteadOfSkippingForever) {
  const std::vector<SourceEvent> base = LoadEvents();
  const std::vector<SourceEvent> again = Shifted(base, -10'000'000, 0);  // 10 s back

  // Without the rule (a bare pipeline) every frame after the jump is lost.
  Pipeline bare(PipelineConfig{}, claw::ClawModel::ThreeFinger());
  Feed(base, &bare);
  const int64_t fused_once = bare.stats().frames_integrated;
  Feed(Shifted(std::vector<SourceEvent>(base.begin(), base.begin() + base.size() / 3), -10'000'000, 0),
       &bare);  // a third is enough to see nothing fused
  bare.Flush();
  EXPECT_EQ(bare.stats().frames_integrated, fused_once);

  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {}, nullptr);
  Feed(base, &sequencer);
  Feed(again, &sequencer);
  const ObjectCloud cloud = sequencer.Finish();
  const SessionCounters c = sequencer.counters();
  EXPECT_EQ(c.clock_jumps, 1);
  EXPECT_EQ(c.frames_fused, 2 * fused_once);
  // Every skipped frame under one reason: the jump's own, the no-pose ones.
  EXPECT_EQ(c.skipped[FrameSkipReason::kClockJump], c.skipped_clock_jump);
  EXPECT_EQ(c.skipped[FrameSkipReason::kNoPoseBefore] + c.skipped[FrameSkipReason::kPoseGap] +
                c.skipped[FrameSkipReason::kNoPoseAfter],
            c.skipped_no_pose);
  EXPECT_EQ(c.frames_since_fused, 0);
  EXPECT_EQ(sequencer.StallReason().find("behind"), std::string::npos);
  // Started over: the model is the one of the events after the jump (the
  // same events as before it, but for their time).
  Pipeline fresh(PipelineConfig{}, claw::ClawModel::ThreeFinger());
  Feed(base, &fresh);
  fresh.Flush();
  EXPECT_TRUE(cloud.points_G == fresh.ExtractCloud().points_G);
}

// A frame waiting for a later state when the clock jumps back is lost to
// the jump, and counted under that reason (not as a missing pose).
TEST(GraspSequencer, AFrameWaitingAtAClockJumpIsSkippedForTheJump) {
  const std::vector<SourceEvent> base = LoadEvents();
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {}, nullptr);
  Feed(base, &sequencer);
  int64_t last_state = 0;
  DepthFrame frame;
  for (const SourceEvent& e : base) {
    if (e.kind == SourceEvent::Kind::kGripperState) last_state = e.gripper.utime;
    if (e.kind == SourceEvent::Kind::kDepth) frame = e.depth;
  }
  frame.utime = last_state + 5000;  // after every state: it waits
  EXPECT_EQ(sequencer.AddDepthFrame(frame), FrameOutcome::kPending);
  const SessionCounters before = sequencer.counters();
  GripperState back;
  for (const SourceEvent& e : base) {
    if (e.kind == SourceEvent::Kind::kGripperState) back = e.gripper;
  }
  back.utime -= 10'000'000;  // 10 s back
  sequencer.AddGripperState(back);
  const SessionCounters c = sequencer.counters();
  EXPECT_EQ(c.clock_jumps, 1);
  EXPECT_EQ(c.skipped_clock_jump, 1);
  EXPECT_EQ(c.skipped[FrameSkipReason::kClockJump], 1);
  EXPECT_EQ(c.skipped[FrameSkipReason::kNoPoseAfter], before.skipped[FrameSkipReason::kNoPoseAfter]);
}

TEST(GraspSequencer, FramesOnAnotherClockThanTheStatesAreReportedAsStalled) {
  const std::vector<SourceEvent> base = LoadEvents();
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {}, nullptr);
  for (const SourceEvent& e : base) {
    if (e.kind == SourceEvent::Kind::kGripperState) sequencer.AddGripperState(e.gripper);
  }
  for (SourceEvent e : base) {
    if (e.kind != SourceEvent::Kind::kDepth) continue;
    e.depth.utime -= 5'000'000;  // the camera's clock 5 s behind the robot's
    sequencer.AddDepthFrame(e.depth);
  }
  const SessionCounters c = sequencer.counters();
  EXPECT_EQ(c.frames_fused, 0);
  EXPECT_GE(c.frames_since_fused, 12);
  const std::string why = sequencer.StallReason();
  EXPECT_NE(why.find("5.0 s behind the gripper states"), std::string::npos) << why;
}

// Posed frames that the pose refinement rejects (the logged poses 10 cm
// off, where the claw is not) are reported as such, not as frames without
// a pose.
TEST(GraspSequencer, FramesThePoseRefinementRejectsAreReportedAsSuch) {
  GraspSequencer sequencer(PipelineConfig{}, claw::ClawModel::ThreeFinger(), {}, nullptr);
  for (SourceEvent e : LoadEvents()) {
    if (e.kind == SourceEvent::Kind::kDepth) {
      sequencer.AddDepthFrame(e.depth);
    } else {
      e.gripper.T_C_G.translation().y() += 0.10;
      sequencer.AddGripperState(e.gripper);
    }
  }
  const SessionCounters c = sequencer.counters();
  EXPECT_EQ(c.frames_fused, 0);
  EXPECT_GE(c.frames_since_fused, 10);
  const std::string why = sequencer.StallReason();
  std::printf("%s\n", why.c_str());
  EXPECT_NE(why.find("pose refinement rejected"), std::string::npos) << why;
  EXPECT_EQ(why.find("no gripper pose"), std::string::npos) << why;
}

}  // namespace
}  // namespace graspfill::rt
