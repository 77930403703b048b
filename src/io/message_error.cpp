// SPDX-License-Identifier: BSD-3-Clause
// The names of the reasons a message is refused (MessageError).
#include "graspfill/io/messages.hpp"

namespace graspfill::io {

const char* MessageErrorName(MessageError reason) {
  switch (reason) {
    case MessageError::kNone:
      return "none";
    case MessageError::kMalformed:
      return "malformed";
    case MessageError::kBadSize:
      return "bad_size";
    case MessageError::kBadIntrinsics:
      return "bad_intrinsics";
    case MessageError::kBadDepthScale:
      return "bad_depth_scale";
    case MessageError::kBadEncoding:
      return "bad_encoding";
    case MessageError::kBadPose:
      return "bad_pose";
    case MessageError::kBadValue:
      return "bad_value";
    case MessageError::kBadTimestamp:
      return "bad_timestamp";
    case MessageError::kIntrinsicsMismatch:
      return "intrinsics_mismatch";
    case MessageError::kNonMonotonicTime:
      return "non_monotonic_time";
    case MessageError::kBadClawName:
      return "bad_claw_name";
    case MessageError::kOutOfLimits:
      return "out_of_limits";
    case MessageError::kClawUnloadable:
      return "claw_unloadable";
    case MessageError::kCount:
      break;
  }
  return "unknown";
}

MessageError MessageErrorFromName(const std::string& name) {
  for (size_t i = 1; i < BadMessageCounts::kNumReasons; ++i) {
    const auto reason = static_cast<MessageError>(i);
    if (name == MessageErrorName(reason)) return reason;
  }
  return MessageError::kNone;
}

}  // namespace graspfill::io
