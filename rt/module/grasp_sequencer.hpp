// SPDX-License-Identifier: BSD-3-Clause
// Grasp after grasp: the Pipeline, started over when the robot's grasp
// changes or the clock jumps back, with counters that add up over the whole
// session. The one place where a session's events meet the pipeline (the
// live module's worker, replay and bench all feed one of these).
//
// The grasp signal (docs/live.md, "Grasp after grasp"): gripper_state_t.grasp_id.
//  - A state whose grasp_id differs from the state before it ends the grasp
//    before (its final model handed to the callback, if any frame was
//    fused) and starts an empty one.
//  - grasp_id 0 after a numbered grasp: the claw released its object; depth
//    frames are not fused (counted as frames_released) until the next
//    number. A session whose states are all 0 is one grasp (as before the
//    signal existed).
//
// Clock jumps: a gripper state or depth frame more than clock_jump_us older
// than the one before it on its own stream means the sender's clock went
// back (a restarted driver or logplayer, an NTP step). Poses from before
// and frames from after cannot be matched, so the grasp starts over: the
// volume and the interpolation buffer are reset (the grasp id is kept), the
// frames waiting for a pose are counted as skipped_clock_jump. Smaller steps
// back are the pipeline's business (states not newer than the last are
// rejected and counted).
//
// Single-threaded, like Pipeline: one thread calls everything.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "graspfill/pipeline/pipeline.hpp"

namespace graspfill::rt {

struct GraspSequencerConfig {
  /// A state or frame this much older than its predecessor on its stream is
  /// a backwards clock jump: the grasp starts over [us] (1 s).
  int64_t clock_jump_us{1000000};

  /// Throws std::invalid_argument naming the field.
  void Validate() const;
};

/// Counters over the whole session (every grasp, every restart).
struct SessionCounters {
  int64_t frames_in{0};
  int64_t frames_fused{0};
  int64_t skipped_no_pose{0};
  int64_t skipped_clock_jump{0};
  int64_t frames_bad{0};
  int64_t frames_dropped{0};   ///< the pipeline's pending queue overflowed
  int64_t frames_released{0};  ///< came while the claw was empty (grasp_id 0)
  int64_t states_in{0};
  int64_t states_rejected{0};
  int64_t clock_jumps{0};
  int64_t grasps_started{0};    ///< numbered grasps begun
  int64_t grasps_completed{0};  ///< final models handed out at a grasp's end
  int64_t grasp_id{0};          ///< the grasp in progress (0: none / not numbered)
  /// Depth frames received since the last one was fused (or since the
  /// start): how long fusion has been stalled, in frames.
  int64_t frames_since_fused{0};
  int64_t last_frame_utime{0};  ///< newest depth frame's utime (bus time)
  int64_t last_state_utime{0};  ///< newest gripper state's utime
  bool holding{true};           ///< the claw holds an object (no release pending)
  /// Every frame not fused, by reason (the pipelines' and the sequencer's:
  /// claw_empty, clock_jump).
  FrameSkipCounts skipped;
};

class GraspSequencer {
 public:
  /// A grasp's final model (is_final set, grasp_id the grasp's) and what
  /// the camera saw of it; called on the caller's thread at the grasp's end.
  using GraspEndCallback = std::function<void(const ObjectCloud&, const evidence::VisibilityRecord&)>;

  /// Throws std::invalid_argument on a bad config.
  GraspSequencer(const PipelineConfig& pipeline, claw::ClawModel claw, const GraspSequencerConfig& config,
                 GraspEndCallback on_grasp_end);

  /// As Pipeline::AddGripperState, after the grasp and clock rules above.
  bool AddGripperState(const GripperState& state);
  /// As Pipeline::AddDepthFrame; a frame that comes while the claw is empty
  /// is not fused (kSkippedNoPose, counted as frames_released).
  FrameOutcome AddDepthFrame(const DepthFrame& frame, std::string* error = nullptr);

  /// The grasp in progress' cloud so far (not final), tagged with its id.
  ObjectCloud ExtractCloud();
  /// Pending frames with no later state are skipped (as Pipeline::Flush);
  /// the grasp goes on.
  void Flush() { pipeline_.Flush(); }
  /// End of the session: the grasp in progress ends; returns its final
  /// model (also handed to the callback). Empty (and no callback) when no
  /// frame of it was fused and an earlier grasp's model was handed out.
  ObjectCloud Finish();

  /// True when the grasp id of `state` would end the grasp in progress
  /// (lets a threaded caller fuse the frames before it first).
  bool EndsGrasp(const GripperState& state) const;
  /// The claw holds an object (no release seen since the last number).
  bool holding() const { return !(numbered_seen_ && counters_.grasp_id == 0); }

  /// Counters over the whole session, including the current grasp's.
  SessionCounters counters() const;
  /// The pipeline's stats summed over the session (stage timings: the
  /// current grasp's, as they average over its frames).
  PipelineStats stats() const;
  /// The current grasp's pipeline (its visibility record, config).
  const Pipeline& pipeline() const { return pipeline_; }
  /// Why the last frames were not fused, for a status ("" if they were).
  std::string StallReason() const;

 private:
  // Sums the pipeline's counters into done_ and resets it.
  void ResetPipeline();
  // Hands out the final model of the grasp in progress (if it fused a
  // frame) and resets. Returns the model.
  ObjectCloud EndGrasp();
  void StartOver();
  void UpdateFused();

  GraspSequencerConfig config_;
  Pipeline pipeline_;
  GraspEndCallback on_grasp_end_;
  PipelineStats done_;        // counters of pipelines reset before
  SessionCounters counters_;  // the fields the pipeline does not count
  bool numbered_seen_{false};
  bool have_frame_{false}, have_state_{false};  // since the last start-over
  int64_t fused_total_at_last_check_{0};
  int64_t refine_rejected_at_last_fused_{0};  // frames refinement or tracking rejected
  refine::RefineStats refine_at_last_fused_;  // this pipeline's, by reason
  int64_t RefineRejectedTotal() const;
  std::string last_error_;
};

}  // namespace graspfill::rt
