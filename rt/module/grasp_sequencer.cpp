// SPDX-License-Identifier: BSD-3-Clause
#include "module/grasp_sequencer.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace graspfill::rt {

void GraspSequencerConfig::Validate() const {
  if (clock_jump_us <= 0) {
    throw std::invalid_argument("GraspSequencerConfig.clock_jump_us must be > 0");
  }
}

namespace {

void AddCounters(const PipelineStats& s, PipelineStats* sum) {
  sum->frames_in += s.frames_in;
  sum->frames_integrated += s.frames_integrated;
  sum->frames_skipped_no_pose += s.frames_skipped_no_pose;
  sum->frames_bad += s.frames_bad;
  sum->frames_skipped_refine += s.frames_skipped_refine;
  sum->frames_decimated += s.frames_decimated;
  sum->frames_skipped_tracking += s.frames_skipped_tracking;
  sum->frames_dropped += s.frames_dropped;
  sum->states_in += s.states_in;
  sum->states_rejected += s.states_rejected;
  sum->claw_rebuilds += s.claw_rebuilds;
  sum->skipped.Add(s.skipped);
}

}  // namespace

GraspSequencer::GraspSequencer(const PipelineConfig& pipeline, claw::ClawModel claw,
                               const GraspSequencerConfig& config, GraspEndCallback on_grasp_end)
    : config_(config), pipeline_(pipeline, std::move(claw)), on_grasp_end_(std::move(on_grasp_end)) {
  config.Validate();
}

void GraspSequencer::ResetPipeline() {
  AddCounters(pipeline_.stats(), &done_);
  pipeline_.Reset();
  refine_at_last_fused_ = pipeline_.stats().refine;  // the new pipeline's (zero)
}

ObjectCloud GraspSequencer::EndGrasp() {
  ObjectCloud cloud;
  pipeline_.Flush();
  if (pipeline_.stats().frames_integrated > 0) {
    cloud = pipeline_.ExtractCloud();
    cloud.grasp_id = counters_.grasp_id;
    cloud.is_final = true;
    ++counters_.grasps_completed;
    if (on_grasp_end_) on_grasp_end_(cloud, pipeline_.visibility());
  }
  ResetPipeline();
  return cloud;
}

void GraspSequencer::StartOver() {
  // The frames still waiting for a pose are lost to the jump: Flush counts
  // them as no-pose skips; move them to their own reason.
  const int64_t no_pose_before = pipeline_.stats().frames_skipped_no_pose;
  pipeline_.Flush();
  const int64_t lost = pipeline_.stats().frames_skipped_no_pose - no_pose_before;
  counters_.skipped_clock_jump += lost;
  done_.frames_skipped_no_pose -= lost;  // summed in by ResetPipeline below
  done_.skipped.Count(FrameSkipReason::kNoPoseAfter, -lost);
  ResetPipeline();
  ++counters_.clock_jumps;
  have_frame_ = have_state_ = false;
}

bool GraspSequencer::EndsGrasp(const GripperState& state) const {
  return state.grasp_id != counters_.grasp_id;
}

bool GraspSequencer::AddGripperState(const GripperState& state) {
  if (have_state_ && state.utime < counters_.last_state_utime - config_.clock_jump_us) {
    StartOver();
  }
  if (EndsGrasp(state)) {
    EndGrasp();
    counters_.grasp_id = state.grasp_id;
    if (state.grasp_id != 0) {
      numbered_seen_ = true;
      ++counters_.grasps_started;
    }
    have_frame_ = have_state_ = false;
  }
  // Out-of-order states are rejected by the pipeline: the newest stays.
  if (!have_state_ || state.utime > counters_.last_state_utime) {
    counters_.last_state_utime = state.utime;
  }
  have_state_ = true;
  const bool accepted = pipeline_.AddGripperState(state);
  UpdateFused();
  return accepted;
}

FrameOutcome GraspSequencer::AddDepthFrame(const DepthFrame& frame, std::string* error) {
  ++counters_.frames_in;
  if (have_frame_ && frame.utime < counters_.last_frame_utime - config_.clock_jump_us) {
    StartOver();
  }
  counters_.last_frame_utime = frame.utime;
  have_frame_ = true;
  ++counters_.frames_since_fused;
  if (!holding()) {
    ++counters_.frames_released;
    last_error_.clear();
    return FrameOutcome::kSkippedNoPose;
  }
  std::string* reason = error != nullptr ? error : &last_error_;
  const FrameOutcome outcome = pipeline_.AddDepthFrame(frame, reason);
  if (outcome == FrameOutcome::kBadFrame) {
    if (reason != &last_error_) last_error_ = *reason;
  } else {
    last_error_.clear();
  }
  UpdateFused();
  return outcome;
}

int64_t GraspSequencer::RefineRejectedTotal() const {
  const PipelineStats& s = pipeline_.stats();
  return done_.frames_skipped_refine + done_.frames_skipped_tracking + s.frames_skipped_refine +
         s.frames_skipped_tracking;
}

void GraspSequencer::UpdateFused() {
  const int64_t fused = done_.frames_integrated + pipeline_.stats().frames_integrated;
  if (fused != fused_total_at_last_check_) {
    fused_total_at_last_check_ = fused;
    counters_.frames_since_fused = 0;
    refine_rejected_at_last_fused_ = RefineRejectedTotal();
    refine_at_last_fused_ = pipeline_.stats().refine;
  }
}

ObjectCloud GraspSequencer::ExtractCloud() {
  ObjectCloud cloud = pipeline_.ExtractCloud();
  cloud.grasp_id = counters_.grasp_id;
  return cloud;
}

ObjectCloud GraspSequencer::Finish() {
  // The pipeline is not reset here: its visibility record stays valid for
  // a caller that repairs the returned cloud. A session that never fused a
  // frame still gets one (empty) final cloud, as replay writes one.
  pipeline_.Flush();
  ObjectCloud cloud;
  if (pipeline_.stats().frames_integrated > 0 || counters_.grasps_completed == 0) {
    cloud = ExtractCloud();
    cloud.is_final = true;
    ++counters_.grasps_completed;
    if (on_grasp_end_) on_grasp_end_(cloud, pipeline_.visibility());
  }
  return cloud;
}

SessionCounters GraspSequencer::counters() const {
  SessionCounters c = counters_;
  const PipelineStats s = stats();
  c.frames_fused = s.frames_integrated;
  c.skipped_no_pose = s.frames_skipped_no_pose;
  c.frames_bad = s.frames_bad;
  c.frames_dropped = s.frames_dropped;
  c.states_in = s.states_in;
  c.states_rejected = s.states_rejected;
  c.skipped = s.skipped;
  c.holding = holding();
  return c;
}

PipelineStats GraspSequencer::stats() const {
  PipelineStats s = pipeline_.stats();
  AddCounters(done_, &s);
  // frames_in counts what reached a pipeline; the released ones too.
  s.frames_in += counters_.frames_released;
  s.skipped.Count(FrameSkipReason::kClawEmpty, counters_.frames_released);
  s.skipped.Count(FrameSkipReason::kClockJump, counters_.skipped_clock_jump);
  return s;
}

std::string GraspSequencer::StallReason() const {
  if (!holding()) return "";
  char text[256];
  if (!last_error_.empty()) {
    std::snprintf(text, sizeof(text), "%lld frames not fused: bad frame (%s)",
                  static_cast<long long>(counters_.frames_since_fused), last_error_.c_str());
    return text;
  }
  if (!have_state_) {
    std::snprintf(text, sizeof(text), "%lld frames not fused: no gripper state received",
                  static_cast<long long>(counters_.frames_since_fused));
    return text;
  }
  const double behind_s = (counters_.last_state_utime - counters_.last_frame_utime) * 1e-6;
  if (std::abs(behind_s) > 1.0) {
    std::snprintf(text, sizeof(text),
                  "%lld frames not fused: depth frames %.1f s %s the gripper states "
                  "(their clocks disagree)",
                  static_cast<long long>(counters_.frames_since_fused), std::abs(behind_s),
                  behind_s > 0 ? "behind" : "ahead of");
    return text;
  }
  // Most of them posed but rejected by the pose refinement (or the object
  // tracking): the logged poses and the depth disagree.
  const int64_t rejected = RefineRejectedTotal() - refine_rejected_at_last_fused_;
  if (rejected > 0 && 2 * rejected >= counters_.frames_since_fused) {
    const refine::RefineStats& now = pipeline_.stats().refine;
    const refine::RefineStats& then = refine_at_last_fused_;
    auto since = [](int64_t a, int64_t b) { return static_cast<long long>(std::max<int64_t>(0, a - b)); };
    std::snprintf(text, sizeof(text),
                  "%lld frames not fused: pose refinement rejected %lld of them (claw not seen "
                  "%lld, not converged %lld, jump %lld): the claw is not where the logged poses "
                  "put it (--no-refine fuses at them)",
                  static_cast<long long>(counters_.frames_since_fused), static_cast<long long>(rejected),
                  since(now.rejected_claw_not_seen, then.rejected_claw_not_seen),
                  since(now.rejected_not_converged, then.rejected_not_converged),
                  since(now.rejected_jump, then.rejected_jump));
    return text;
  }
  std::snprintf(text, sizeof(text), "%lld frames not fused: no gripper pose within %.0f ms of them",
                static_cast<long long>(counters_.frames_since_fused),
                pipeline_.config().max_pose_gap_us / 1000.0);
  return text;
}

}  // namespace graspfill::rt
