// SPDX-License-Identifier: BSD-3-Clause
// Test tool: listens to module_status_t on a channel until none came for
// <quiet-ms> after the first, <timeout-ms> in all, or SIGTERM / SIGINT (the
// publisher is gone), and prints how regularly they came and what the last
// one said:
//   statuses=<n> max_gap_ms=<ms> frames_used=<n> decode_errors=<n> state=<text>
//   reason <name> <count>        (one line per non-zero reason)
// max_gap_ms is the longest time between two statuses, or between the first
// message on <start-channel> (if given: the session's first depth frame)
// and the first status.
// usage: status_subscriber <lcm-url> <channel> <quiet-ms> <timeout-ms> [<start-channel>]
// Exit: 0 at least one status, 1 usage, 2 none, 3 undecodable status, 4 LCM error.
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "graspfill/io/messages.hpp"
#include "test_cloud.hpp"

namespace {

using Clock = std::chrono::steady_clock;
std::atomic<bool> g_stop{false};

// Never throws (called from LCM's C dispatch): records what came.
class Receiver {
 public:
  void OnStart(const lcm::ReceiveBuffer*, const std::string&) {
    if (!started) last_arrival = Clock::now();
    started = true;
  }
  void OnMessage(const lcm::ReceiveBuffer* buffer, const std::string&) {
    const Clock::time_point now = Clock::now();
    if (count > 0 || started) {
      max_gap_ms =
          std::max(max_gap_ms, std::chrono::duration<double, std::milli>(now - last_arrival).count());
    }
    last_arrival = now;
    ++count;
    std::string error;
    if (!graspfill::io::DecodeModuleStatus(buffer->data, buffer->data_size, &last, &error)) {
      bad = true;
      std::fprintf(stderr, "status_subscriber: %s\n", error.c_str());
    }
  }
  int count{0};
  bool started{false};
  bool bad{false};
  double max_gap_ms{0.0};
  Clock::time_point last_arrival;
  graspfill::io::ModuleStatus last;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: %s <lcm-url> <channel> <quiet-ms> <timeout-ms> [<start-channel>]\n",
                 argv[0]);
    return 1;
  }
  const std::string url = argv[1];
  const std::string channel = argv[2];
  const int quiet_ms = std::atoi(argv[3]);
  const int timeout_ms = std::atoi(argv[4]);
  if (!graspfill::rt::testing::UrlAllowed(url)) return 1;
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "status_subscriber: LCM setup failed for %s\n", url.c_str());
    return 4;
  }
  Receiver receiver;
  lcm.subscribe(channel, &Receiver::OnMessage, &receiver);
  lcm::Subscription* start = nullptr;
  if (argc == 6) start = lcm.subscribe(argv[5], &Receiver::OnStart, &receiver);
  std::signal(SIGTERM, [](int) { g_stop = true; });
  std::signal(SIGINT, [](int) { g_stop = true; });
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const Clock::time_point now = Clock::now();
    if (now >= deadline || g_stop) break;
    if (receiver.count > 0 && now - receiver.last_arrival >= std::chrono::milliseconds(quiet_ms)) {
      break;
    }
    if (start != nullptr && receiver.started) {  // no need to see the rest
      lcm.unsubscribe(start);
      start = nullptr;
    }
    if (lcm.handleTimeout(50) < 0) {
      if (g_stop) break;  // the signal interrupted the wait
      std::fprintf(stderr, "status_subscriber: LCM handle error\n");
      return 4;
    }
  }
  if (receiver.count == 0) {
    std::fprintf(stderr, "status_subscriber: no status on %s\n", channel.c_str());
    return 2;
  }
  const graspfill::io::ModuleStatus& s = receiver.last;
  std::printf("statuses=%d max_gap_ms=%.0f frames_used=%lld decode_errors=%lld state=%s\n", receiver.count,
              receiver.max_gap_ms, static_cast<long long>(s.frames_used),
              static_cast<long long>(s.decode_errors), s.state.c_str());
  for (size_t i = 1; i < graspfill::io::BadMessageCounts::kNumReasons; ++i) {
    if (s.bad_messages.by_reason[i] == 0) continue;
    std::printf("reason %s %lld\n",
                graspfill::io::MessageErrorName(static_cast<graspfill::io::MessageError>(i)),
                static_cast<long long>(s.bad_messages.by_reason[i]));
  }
  return receiver.bad ? 3 : 0;
}
