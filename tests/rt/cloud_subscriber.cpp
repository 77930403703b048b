// SPDX-License-Identifier: BSD-3-Clause
// Test tool: waits for one object_cloud_t on a channel (whole, or joined
// from its object_cloud_chunk_t slices) and prints "points=<n>
// checksum=<hex>" to stdout.
// usage: cloud_subscriber <lcm-url> <channel> <timeout-ms>
// Exit: 0 received, 1 usage, 2 timeout, 3 undecodable message, 4 LCM error.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "graspfill/io/cloud_chunks.hpp"
#include "graspfill/io/messages.hpp"
#include "test_cloud.hpp"

namespace {

// Never throws (called from LCM's C dispatch): records the outcome.
class Receiver {
 public:
  void OnMessage(const lcm::ReceiveBuffer* buffer, const std::string&) {
    using Result = graspfill::io::CloudChunkAssembler::Result;
    const Result r = assembler.Add(buffer->data, buffer->data_size, &error);
    if (r == Result::kPending || r == Result::kRepeat) return;
    done = true;
    decoded =
        r == Result::kComplete &&
        graspfill::io::DecodeObjectCloud(assembler.cloud().data(), assembler.cloud().size(), &cloud, &error);
  }
  graspfill::io::CloudChunkAssembler assembler;
  bool done{false};
  bool decoded{false};
  graspfill::ObjectCloud cloud;
  std::string error;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <lcm-url> <channel> <timeout-ms>\n", argv[0]);
    return 1;
  }
  const std::string url = argv[1];
  const std::string channel = argv[2];
  const int timeout_ms = std::atoi(argv[3]);
  if (!graspfill::rt::testing::UrlAllowed(url)) return 1;

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "cloud_subscriber: LCM setup failed for %s\n", url.c_str());
    return 4;
  }
  Receiver receiver;
  lcm.subscribe(channel, &Receiver::OnMessage, &receiver);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!receiver.done) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now())
            .count();
    if (left <= 0) {
      std::fprintf(stderr, "cloud_subscriber: timeout after %d ms on %s\n", timeout_ms, channel.c_str());
      return 2;
    }
    if (lcm.handleTimeout(static_cast<int>(left)) < 0) {
      std::fprintf(stderr, "cloud_subscriber: LCM handle error\n");
      return 4;
    }
  }
  if (!receiver.decoded) {
    std::fprintf(stderr, "cloud_subscriber: %s\n", receiver.error.c_str());
    return 3;
  }
  std::printf("%s\n", graspfill::rt::testing::SummaryLine(receiver.cloud).c_str());
  return 0;
}
