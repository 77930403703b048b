// SPDX-License-Identifier: BSD-3-Clause
// module_status_t <-> ModuleStatus.
#include "graspfill/io/messages.hpp"

#include "wire.hpp"

#include <array>
#include <optional>

#include <graspfill/module_status_t.hpp>

namespace graspfill::io {
using namespace wire;

std::vector<uint8_t> EncodeModuleStatus(const ModuleStatus& status) {
  graspfill::module_status_t msg{};
  msg.utime = status.utime;
  msg.frames_in = status.frames_in;
  msg.frames_used = status.frames_used;
  msg.frames_skipped = status.frames_skipped;
  msg.frames_dropped = status.frames_dropped;
  msg.last_frame_ms = status.last_frame_ms;
  msg.state = status.state;
  msg.state_code = static_cast<int8_t>(status.state_code);
  msg.state_detail = status.state_detail;
  msg.frames_skipped_no_pose = status.frames_skipped_no_pose;
  msg.frames_skipped_clock_jump = status.frames_skipped_clock_jump;
  msg.frames_bad = status.frames_bad;
  msg.frames_skipped_refine = status.frames_skipped_refine;
  msg.decode_errors = status.decode_errors;
  msg.clock_jumps = status.clock_jumps;
  msg.repairs_done = status.repairs_done;
  msg.repairs_superseded = status.repairs_superseded;
  msg.repairs_failed = status.repairs_failed;
  msg.grasp_id = status.grasp_id;
  msg.grasps_completed = status.grasps_completed;
  msg.latency_ms_p50 = status.latency_ms_p50;
  msg.latency_ms_p95 = status.latency_ms_p95;
  msg.latency_ms_p99 = status.latency_ms_p99;
  msg.latency_ms_max = status.latency_ms_max;
  msg.clouds_published = status.clouds_published;
  msg.repair_updates = status.repair_updates;
  msg.repairs_full = status.repairs_full;
  msg.update_ms_p50 = status.update_ms_p50;
  msg.update_ms_p99 = status.update_ms_p99;
  msg.full_repair_ms_p50 = status.full_repair_ms_p50;
  msg.full_repair_ms_p99 = status.full_repair_ms_p99;
  msg.rss_mb = status.rss_mb;
  for (size_t i = 1; i < BadMessageCounts::kNumReasons; ++i) {
    msg.bad_message_reasons.push_back(MessageErrorName(static_cast<MessageError>(i)));
    msg.bad_messages.push_back(status.bad_messages.by_reason[i]);
  }
  msg.num_bad_message_reasons = static_cast<int32_t>(msg.bad_messages.size());
  for (size_t i = 1; i < kNumFrameSkipReasons; ++i) {
    msg.skip_reasons.push_back(FrameSkipReasonName(static_cast<FrameSkipReason>(i)));
    msg.frames_skipped_by_reason.push_back(status.frames_skipped_by_reason.by_reason[i]);
  }
  msg.num_skip_reasons = static_cast<int32_t>(msg.frames_skipped_by_reason.size());
  return EncodeMessage(msg);
}

static bool DecodeModuleStatusImpl(const void* data, size_t size, ModuleStatus* out, std::string* error) {
  if (!CheckBuffer(data, size, out, "module_status_t", error)) return false;
  WireReader r(data, size);
  if (!r.Hash(graspfill::module_status_t::getHash()) || !r.Skip(5 * 8 + 8) || !r.SkipString() || !r.Skip(1) ||
      !r.SkipString() || !r.Skip(11 * 8 + 5 * 8 + 7 * 8)) {
    SetError(error, "module_status_t: malformed message");
    return false;
  }
  // Two named count arrays: the bad messages', the skipped frames'.
  bool ok = true;
  for (int array = 0; ok && array < 2; ++array) {
    int32_t num_reasons = 0;
    ok = r.Count(&num_reasons, 4 + 1 + 8);
    for (int32_t i = 0; ok && i < num_reasons; ++i) ok = r.SkipString();
    ok = ok && r.Skip(8 * static_cast<size_t>(num_reasons));
  }
  if (!ok || r.remaining() != 0) {
    SetError(error, "module_status_t: malformed message");
    return false;
  }
  graspfill::module_status_t msg{};
  if (!DecodeMessage(data, size, &msg, error)) return false;
  out->utime = msg.utime;
  out->frames_in = msg.frames_in;
  out->frames_used = msg.frames_used;
  out->frames_skipped = msg.frames_skipped;
  out->frames_dropped = msg.frames_dropped;
  out->last_frame_ms = msg.last_frame_ms;
  out->state = msg.state;
  out->state_code = static_cast<ModuleState>(msg.state_code);
  out->state_detail = msg.state_detail;
  out->frames_skipped_no_pose = msg.frames_skipped_no_pose;
  out->frames_skipped_clock_jump = msg.frames_skipped_clock_jump;
  out->frames_bad = msg.frames_bad;
  out->frames_skipped_refine = msg.frames_skipped_refine;
  out->decode_errors = msg.decode_errors;
  out->clock_jumps = msg.clock_jumps;
  out->repairs_done = msg.repairs_done;
  out->repairs_superseded = msg.repairs_superseded;
  out->repairs_failed = msg.repairs_failed;
  out->grasp_id = msg.grasp_id;
  out->grasps_completed = msg.grasps_completed;
  out->latency_ms_p50 = msg.latency_ms_p50;
  out->latency_ms_p95 = msg.latency_ms_p95;
  out->latency_ms_p99 = msg.latency_ms_p99;
  out->latency_ms_max = msg.latency_ms_max;
  out->clouds_published = msg.clouds_published;
  out->repair_updates = msg.repair_updates;
  out->repairs_full = msg.repairs_full;
  out->update_ms_p50 = msg.update_ms_p50;
  out->update_ms_p99 = msg.update_ms_p99;
  out->full_repair_ms_p50 = msg.full_repair_ms_p50;
  out->full_repair_ms_p99 = msg.full_repair_ms_p99;
  out->rss_mb = msg.rss_mb;
  out->bad_messages = BadMessageCounts{};
  std::array<bool, BadMessageCounts::kNumReasons> seen{};
  for (size_t i = 0; i < msg.bad_message_reasons.size(); ++i) {
    const MessageError reason = MessageErrorFromName(msg.bad_message_reasons[i]);
    const auto index = static_cast<size_t>(reason);
    if (reason == MessageError::kNone || seen[index] || msg.bad_messages[i] < 0) {
      SetError(error,
               "module_status_t: bad message reason '" + msg.bad_message_reasons[i] +
                   "' unknown, repeated or with a negative count",
               MessageError::kBadValue);
      return false;
    }
    seen[index] = true;
    out->bad_messages.by_reason[index] = msg.bad_messages[i];
  }
  out->frames_skipped_by_reason = FrameSkipCounts{};
  std::array<bool, kNumFrameSkipReasons> skip_seen{};
  for (size_t i = 0; i < msg.skip_reasons.size(); ++i) {
    const std::optional<FrameSkipReason> reason = FrameSkipReasonFromName(msg.skip_reasons[i]);
    const auto index = static_cast<size_t>(reason.value_or(FrameSkipReason::kNone));
    if (!reason || *reason == FrameSkipReason::kNone || skip_seen[index] ||
        msg.frames_skipped_by_reason[i] < 0) {
      SetError(error,
               "module_status_t: skip reason '" + msg.skip_reasons[i] +
                   "' unknown, repeated or with a negative count",
               MessageError::kBadValue);
      return false;
    }
    skip_seen[index] = true;
    out->frames_skipped_by_reason.by_reason[index] = msg.frames_skipped_by_reason[i];
  }
  return true;
}

bool DecodeModuleStatus(const void* data, size_t size, ModuleStatus* out, std::string* error,
                        MessageError* reason) {
  return WithReason(reason, [&] { return DecodeModuleStatusImpl(data, size, out, error); });
}

}  // namespace graspfill::io
