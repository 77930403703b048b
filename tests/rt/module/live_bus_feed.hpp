// SPDX-License-Identifier: BSD-3-Clause
// Feeds a LiveSession bytes as the bus would (its subscriber's handlers,
// no socket) and checks, after every message, what its status must always
// say whatever came: every message accepted or counted as bad exactly once,
// the counts by reason summing to decode_errors, a known state. Shared by
// the randomized test (live_session_bus_test.cc) and the fuzzer
// (tests/fuzz/fuzz_live_bus.cpp).
#pragma once

#include <cstdint>
#include <string>

#include "module/live_session.hpp"

namespace graspfill::rt::testing {

enum class BusChannel { kDepth, kGripperState, kSession };

/// "" when the status of `live`, after `fed` messages through Feed, is
/// sane; else what is not. The session must take depth from the bus.
inline std::string CheckBusStatus(LiveSession& live, int64_t fed) {
  const LcmBusSubscriber& bus = live.subscriber();
  const int64_t accepted = bus.states_received() + bus.depth_received() + bus.sessions_received();
  if (accepted + bus.decode_errors() != fed) {
    return "messages fed " + std::to_string(fed) + " != accepted " + std::to_string(accepted) +
           " + rejected " + std::to_string(bus.decode_errors());
  }
  const io::ModuleStatus s = live.Status();
  if (s.decode_errors != s.bad_messages.total()) return "decode_errors != the sum by reason";
  for (size_t i = 0; i < io::BadMessageCounts::kNumReasons; ++i) {
    if (s.bad_messages.by_reason[i] < 0) return "a negative count";
  }
  if (s.bad_messages.by_reason[0] != 0) return "a count for reason 'none'";
  const int64_t unloadable = s.bad_messages[io::MessageError::kClawUnloadable];
  if (s.decode_errors != bus.decode_errors() + unloadable) {
    return "decode_errors != the bus's rejects + claw_unloadable";
  }
  if (unloadable > bus.sessions_received()) return "more unloadable claws than descriptions";
  if (s.frames_in > bus.depth_received()) return "frames_in > depth frames accepted";
  if (s.frames_used > s.frames_in || s.frames_used < 0) return "frames_used outside 0..frames_in";
  const auto code = static_cast<int>(s.state_code);
  if (code < static_cast<int>(io::ModuleState::kWaiting) ||
      code > static_cast<int>(io::ModuleState::kError)) {
    return "state_code " + std::to_string(code);
  }
  if (s.state.empty()) return "no state text";
  return "";
}

/// Hands one message to the subscriber's handler for `channel`.
inline void FeedBus(LiveSession& live, BusChannel channel, const void* data, size_t size) {
  LcmBusSubscriber& bus = live.subscriber();
  switch (channel) {
    case BusChannel::kDepth:
      bus.HandleDepth(data, size);
      break;
    case BusChannel::kGripperState:
      bus.HandleGripperState(data, size);
      break;
    case BusChannel::kSession:
      bus.HandleSession(data, size);
      break;
  }
}

}  // namespace graspfill::rt::testing
