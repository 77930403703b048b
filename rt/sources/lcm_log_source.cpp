// SPDX-License-Identifier: BSD-3-Clause
#include "sources/lcm_log_source.hpp"

#include "sources/session_overrides.hpp"

#include <algorithm>
#include <stdexcept>

namespace graspfill::rt {

LcmLogSource::LcmLogSource(const Config& config)
    : config_(config),
      reader_(std::make_unique<io::LcmLogReader>(config.path)),
      T_C_B_(config.overrides.T_C_B),
      intrinsics_(config.overrides.intrinsics) {}

LcmLogSource::~LcmLogSource() = default;

FrameResult LcmLogSource::Next(SourceEvent* event) {
  while (!ended_) {
    const io::LogReadResult read = reader_->Next(&log_event_);
    if (read != io::LogReadResult::kEvent) {
      ended_ = true;
      truncated_ = read != io::LogReadResult::kEnd;
      partial_last_event_ = read == io::LogReadResult::kTruncated;
      break;
    }
    ++events_read_;
    const io::LogEvent* log_event = &log_event_;
    const std::string& channel = log_event->channel;
    if (std::find(channels_seen_.begin(), channels_seen_.end(), channel) == channels_seen_.end()) {
      channels_seen_.push_back(channel);
    }
    const size_t size = log_event->data.size();
    const uint8_t* data = log_event->data.data();
    if (channel == config_.channels.depth) {
      event->kind = SourceEvent::Kind::kDepth;
      if (!io::DecodeDepthImage(data, size, &event->depth, &event->error, nullptr,
                                config_.max_depth_pixels) ||
          !ApplyIntrinsicsOverride(intrinsics_, &event->depth, &event->error)) {
        return FrameResult::kBadFrame;
      }
      return FrameResult::kOk;
    }
    if (channel == config_.channels.gripper_state) {
      event->kind = SourceEvent::Kind::kGripperState;
      if (!io::DecodeGripperState(data, size, T_C_B_, &event->gripper, &event->error)) {
        return FrameResult::kBadFrame;
      }
      event->gripper.utime += config_.overrides.gripper_clock_offset_us;
      return FrameResult::kOk;
    }
    if (channel == config_.channels.session) {
      event->kind = SourceEvent::Kind::kSession;
      if (!io::DecodeSessionDescription(data, size, &event->session, &event->error)) {
        return FrameResult::kBadFrame;
      }
      ++sessions_read_;
      if (config_.overrides.T_C_B_from_session) T_C_B_ = event->session.T_C_B;
      if (config_.overrides.intrinsics_from_session) intrinsics_ = event->session.intrinsics;
      if (config_.session_events) return FrameResult::kOk;
      continue;
    }
    ++skipped_other_channels_;
  }
  return FrameResult::kEndOfStream;
}

}  // namespace graspfill::rt
