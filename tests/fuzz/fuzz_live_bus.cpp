// SPDX-License-Identifier: BSD-3-Clause
// The live session's bus input on arbitrary bytes (issue 36): a sequence of
// messages (depth images, gripper states, session descriptions) handed to
// a LiveSession through its bus subscriber's handlers, the path the bus
// takes, with the status checked after each (live_bus_feed.hpp: every
// message accepted or counted once, the counts by reason summing up, a
// known state). Session descriptions' claws are built as `live` builds
// them, with no local mesh root: nothing is read from or written to disk.
//
// Input: records of [channel byte (mod 3: depth, gripper state, session
// description)][length, 2 bytes little-endian][that many bytes], until the
// input ends (a short last record takes what is left).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include "claw_option.hpp"
#include "fuzz_check.hpp"
#include "live_bus_feed.hpp"
#include "module/live_session.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rt::LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.depth_from_bus = true;
  config.repair = false;
  config.module.frame_queue_capacity = 2;  // 4096 x 4096 frames are 64 MB each
  // The bus path is fuzzed, not the per-frame algorithms (their own
  // targets and tests): no registration, no safe bound carved per frame.
  config.module.pipeline.refine.enabled = false;
  config.module.pipeline.visibility.safe_bound_voxel_m = 0.0;
  config.build_session_claw = [](const io::SessionDescription& s) { return cli::MakeSessionClaw(s, ""); };
  config.same_claw = cli::SameClaw;
  config.on_notice = [](const std::string&) {};
  rt::LiveSession live(config);
  io::SessionDescription in_use;
  cli::DescribeBuiltinClaw("three-finger", {}, &in_use);
  live.Begin(claw::ClawModel::ThreeFinger(), in_use);

  int64_t fed = 0;
  size_t at = 0;
  while (at < size) {
    const auto channel = static_cast<rt::testing::BusChannel>(data[at] % 3);
    size_t length = 0;
    if (at + 3 <= size) length = data[at + 1] | (static_cast<size_t>(data[at + 2]) << 8);
    at = at + 3 <= size ? at + 3 : size;
    if (length > size - at) length = size - at;
    rt::testing::FeedBus(live, channel, data + at, length);
    at += length;
    ++fed;
    const std::string broken = rt::testing::CheckBusStatus(live, fed);
    if (!broken.empty()) {
      std::fprintf(stderr, "after message %lld: %s\n", static_cast<long long>(fed), broken.c_str());
    }
    FUZZ_CHECK(broken.empty());
  }
  // The claws' verdicts in (a URDF of many links may take a while), then
  // the status once more.
  FUZZ_CHECK(live.WaitSessionChecks(std::chrono::seconds(8)));
  FUZZ_CHECK(rt::testing::CheckBusStatus(live, fed).empty());
  return 0;
}
