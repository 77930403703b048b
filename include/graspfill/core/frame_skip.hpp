// SPDX-License-Identifier: BSD-3-Clause
// Why a depth frame was not fused: one reason per skipped frame, from the
// Pipeline (pipeline/pipeline.hpp) or, for the last two, from rt's grasp
// sequencer; counted per reason in the pipeline's stats, the session's
// report and module_status_t.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace graspfill {

enum class FrameSkipReason : uint8_t {
  kNone = 0,            ///< fused
  kBadFrame,            ///< wrong size, bad intrinsics, or not the first frame's size
  kNoPoseBefore,        ///< older than every gripper state kept
  kPoseGap,             ///< the gripper states around it too far apart (max_pose_gap_us)
  kNoPoseAfter,         ///< the stream ended before a gripper state after it
  kPendingFull,         ///< dropped: max_pending_frames were already waiting for a state
  kClawNotSeen,         ///< pose refinement: too few depth points near the predicted claw
  kRefineNotConverged,  ///< pose refinement: the registration did not converge
  kRefineJump,          ///< pose refinement: a correction beyond its limits
  kTrackTooFewPoints,   ///< object tracking: too few object pixels or matches
  kTrackNotConverged,   ///< object tracking: no convergence or too high a residual
  kTrackJump,           ///< object tracking: a step beyond its limits
  kClawEmpty,           ///< (sequencer) came while the claw held nothing (grasp_id 0)
  kClockJump,           ///< (sequencer) waiting for a pose when the clock jumped back
  kCount,               ///< number of values, not a reason
};

constexpr size_t kNumFrameSkipReasons = static_cast<size_t>(FrameSkipReason::kCount);

/// The reason's name in reports and module_status_t: "none", "bad_frame",
/// "no_pose_before", "pose_gap", "no_pose_after", "pending_full",
/// "claw_not_seen", "refine_not_converged", "refine_jump",
/// "track_too_few_points", "track_not_converged", "track_jump",
/// "claw_empty", "clock_jump".
const char* FrameSkipReasonName(FrameSkipReason reason);
/// The reason of a name FrameSkipReasonName gives; none for any other text.
std::optional<FrameSkipReason> FrameSkipReasonFromName(const std::string& name);

/// Skipped frames per reason, cumulative.
struct FrameSkipCounts {
  /// Indexed by FrameSkipReason (kNone stays 0).
  std::array<int64_t, kNumFrameSkipReasons> by_reason{};
  int64_t operator[](FrameSkipReason reason) const { return by_reason[static_cast<size_t>(reason)]; }
  void Count(FrameSkipReason reason, int64_t n = 1) { by_reason[static_cast<size_t>(reason)] += n; }
  void Add(const FrameSkipCounts& other) {
    for (size_t i = 0; i < kNumFrameSkipReasons; ++i) by_reason[i] += other.by_reason[i];
  }
  int64_t total() const {
    int64_t sum = 0;
    for (int64_t n : by_reason) sum += n;
    return sum;
  }
  bool operator==(const FrameSkipCounts& o) const { return by_reason == o.by_reason; }
};

/// The non-zero counts as text, in the enum's order: "pose_gap 3,
/// claw_not_seen 2" ("" when none).
std::string FrameSkipText(const FrameSkipCounts& counts);

}  // namespace graspfill
