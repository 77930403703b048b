// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/frame_skip.hpp"

namespace graspfill {

const char* FrameSkipReasonName(FrameSkipReason reason) {
  switch (reason) {
    case FrameSkipReason::kNone:
      return "none";
    case FrameSkipReason::kBadFrame:
      return "bad_frame";
    case FrameSkipReason::kNoPoseBefore:
      return "no_pose_before";
    case FrameSkipReason::kPoseGap:
      return "pose_gap";
    case FrameSkipReason::kNoPoseAfter:
      return "no_pose_after";
    case FrameSkipReason::kPendingFull:
      return "pending_full";
    case FrameSkipReason::kClawNotSeen:
      return "claw_not_seen";
    case FrameSkipReason::kRefineNotConverged:
      return "refine_not_converged";
    case FrameSkipReason::kRefineJump:
      return "refine_jump";
    case FrameSkipReason::kTrackTooFewPoints:
      return "track_too_few_points";
    case FrameSkipReason::kTrackNotConverged:
      return "track_not_converged";
    case FrameSkipReason::kTrackJump:
      return "track_jump";
    case FrameSkipReason::kClawEmpty:
      return "claw_empty";
    case FrameSkipReason::kClockJump:
      return "clock_jump";
    case FrameSkipReason::kCount:
      break;
  }
  return "unknown";
}

std::optional<FrameSkipReason> FrameSkipReasonFromName(const std::string& name) {
  for (size_t i = 0; i < kNumFrameSkipReasons; ++i) {
    const auto reason = static_cast<FrameSkipReason>(i);
    if (name == FrameSkipReasonName(reason)) return reason;
  }
  return std::nullopt;
}

std::string FrameSkipText(const FrameSkipCounts& counts) {
  std::string text;
  for (size_t i = 1; i < kNumFrameSkipReasons; ++i) {
    if (counts.by_reason[i] == 0) continue;
    if (!text.empty()) text += ", ";
    text += FrameSkipReasonName(static_cast<FrameSkipReason>(i));
    text += " " + std::to_string(counts.by_reason[i]);
  }
  return text;
}

}  // namespace graspfill
