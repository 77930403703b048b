// SPDX-License-Identifier: BSD-3-Clause
// Bus input is data, never control (issue 36), deterministically: the
// bundled recording's messages fed to a live session through its bus
// subscriber's handlers (as the bus would, no socket), mixed by a seeded
// generator with copies damaged past decoding (cut short, a flipped type
// hash: the fuzzer tries the rest) and with crafted session descriptions
// (claw names that are paths, values beyond the config file's limits,
// claws that cannot be built, another claw). After every message the status
// must be sane (live_bus_feed.hpp); at the end every crafted description
// is counted by its reason, told once per reason, the other claw warned
// about once, and the session fused.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <graspfill/session_description_t.hpp>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "claw_option.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "live_bus_feed.hpp"
#include "module/live_session.hpp"

namespace graspfill::rt {
namespace {

using testing::BusChannel;
using Msg = graspfill::session_description_t;

const std::string kBundled = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";

std::vector<uint8_t> Encode(const Msg& msg) {
  std::vector<uint8_t> out(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

// Crafted descriptions and the reason each must be counted under (kNone:
// accepted).
struct Crafted {
  std::vector<uint8_t> bytes;
  io::MessageError reason;
};

std::vector<Crafted> CraftedDescriptions() {
  Msg base{};
  base.claw_kind = Msg::CLAW_BUILTIN;
  base.claw_name = "three-finger";
  base.claw_text = cli::ProceduralClawText({});
  base.T_C_B_orientation[0] = 1.0;
  std::vector<Crafted> out;
  out.push_back({Encode(base), io::MessageError::kNone});  // the claw in use
  Msg m = base;
  m.claw_name = "parallel";  // another claw
  out.push_back({Encode(m), io::MessageError::kNone});
  m = base;
  m.claw_kind = Msg::CLAW_DESCRIPTION;
  m.claw_text = R"({"links": [{"name": "palm"}]})";
  m.claw_name = "../../victim";
  out.push_back({Encode(m), io::MessageError::kBadClawName});
  m.claw_name = "/tmp/victim";
  out.push_back({Encode(m), io::MessageError::kBadClawName});
  m = base;
  m.voxel_m = 1.0;
  out.push_back({Encode(m), io::MessageError::kOutOfLimits});
  m = base;
  m.has_workspace_box = 1;
  for (int k = 0; k < 3; ++k) {
    m.workspace_min[k] = -1e300;
    m.workspace_max[k] = 1e300;
  }
  out.push_back({Encode(m), io::MessageError::kOutOfLimits});
  m = base;
  m.claw_kind = Msg::CLAW_URDF;
  m.claw_name = "missing";
  m.claw_text = R"(<robot name="r"><link name="a"><collision><geometry>)"
                R"(<mesh filename="meshes/missing.stl"/></geometry></collision></link></robot>)";
  out.push_back({Encode(m), io::MessageError::kClawUnloadable});
  m = base;
  m.claw_kind = Msg::CLAW_DESCRIPTION;
  m.claw_name = "escape";
  m.claw_text = R"({"links": [{"name": "palm", "mesh": "/etc/passwd"}]})";
  out.push_back({Encode(m), io::MessageError::kClawUnloadable});
  return out;
}

TEST(LiveSessionBus, WhateverTheBusSaysTheSessionGoesOn) {
  LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.depth_from_bus = true;
  config.repair = false;
  config.module.frame_queue_capacity = 1000;  // no drops: fusion is checked
  config.module.state_queue_capacity = 10000;
  config.limits.idle_exit_s = 0.5;  // Run: after the feed
  config.limits.duration_s = 60;
  config.build_session_claw = [](const io::SessionDescription& s) { return cli::MakeSessionClaw(s, ""); };
  config.same_claw = cli::SameClaw;
  std::mutex mutex;
  std::vector<std::string> notices, other_claws;
  config.on_notice = [&](const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex);
    notices.push_back(text);
  };
  config.on_other_claw = [&](const io::SessionDescription& s) {
    std::lock_guard<std::mutex> lock(mutex);
    other_claws.push_back(s.claw_name);
  };
  LiveSession live(config);
  io::SessionDescription in_use;
  cli::DescribeBuiltinClaw("three-finger", {}, &in_use);
  live.Begin(claw::ClawModel::ThreeFinger(), in_use);

  const io::ChannelNames channels;
  const std::vector<Crafted> crafted = CraftedDescriptions();
  std::vector<int64_t> expected(io::BadMessageCounts::kNumReasons, 0);
  std::mt19937 rng(36);
  std::uniform_int_distribution<int> percent(0, 99);
  io::LcmLogReader reader(kBundled);
  io::LogEvent event;
  int64_t fed = 0;
  int64_t damaged = 0;
  int parallel_sent = 0;
  while (reader.Next(&event) == io::LogReadResult::kEvent) {
    const BusChannel channel =
        event.channel == channels.depth ? BusChannel::kDepth : BusChannel::kGripperState;
    if (event.channel != channels.depth && event.channel != channels.gripper_state) continue;
    const int roll = percent(rng);
    if (roll < 15) {  // a crafted description before the event
      const size_t k = std::uniform_int_distribution<size_t>(0, crafted.size() - 1)(rng);
      const std::vector<uint8_t>& bytes = crafted[k].bytes;
      testing::FeedBus(live, BusChannel::kSession, bytes.data(), bytes.size());
      ++fed;
      ++expected[static_cast<size_t>(crafted[k].reason)];
      parallel_sent += k == 1;
      // The claw's verdict before the next one: every unloadable counted.
      ASSERT_TRUE(live.WaitSessionChecks(std::chrono::seconds(30)));
      ASSERT_EQ(testing::CheckBusStatus(live, fed), "") << "after crafted description " << k;
    }
    std::vector<uint8_t> data = event.data;
    if (roll >= 90) {  // damaged so that it cannot decode: cut short, or the type hash
      if (percent(rng) < 50) {
        data.resize(std::uniform_int_distribution<size_t>(0, data.size() - 1)(rng));
      } else {
        data[static_cast<size_t>(percent(rng) % 8)] ^= static_cast<uint8_t>(1u << (percent(rng) % 8));
      }
      ++damaged;
    }
    testing::FeedBus(live, channel, data.data(), data.size());
    ++fed;
    ASSERT_EQ(testing::CheckBusStatus(live, fed), "") << "after message " << fed;
  }
  ASSERT_TRUE(live.WaitSessionChecks(std::chrono::seconds(30)));
  ASSERT_EQ(testing::CheckBusStatus(live, fed), "");

  const io::ModuleStatus status = live.Status();
  for (io::MessageError reason :
       {io::MessageError::kBadClawName, io::MessageError::kOutOfLimits, io::MessageError::kClawUnloadable}) {
    SCOPED_TRACE(io::MessageErrorName(reason));
    const int64_t sent = expected[static_cast<size_t>(reason)];
    ASSERT_GT(sent, 1) << "the seed must send each kind more than once";
    EXPECT_EQ(status.bad_messages[reason], sent);
    // Told once, naming the reason.
    std::lock_guard<std::mutex> lock(mutex);
    int told = 0;
    for (const std::string& n : notices) {
      const std::string said = std::string("rejected (") + io::MessageErrorName(reason) + ")";
      told += n.find(said) != std::string::npos;
    }
    EXPECT_EQ(told, 1);
  }
  EXPECT_GT(damaged, 0);
  EXPECT_EQ(status.decode_errors, damaged + expected[static_cast<size_t>(io::MessageError::kBadClawName)] +
                                      expected[static_cast<size_t>(io::MessageError::kOutOfLimits)] +
                                      expected[static_cast<size_t>(io::MessageError::kClawUnloadable)]);
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_GT(parallel_sent, 1);
    EXPECT_EQ(other_claws, std::vector<std::string>{"parallel"});  // once
  }
  // And it fused: the session ends as `live` ends it (idle), its frames
  // flushed through the module's worker.
  const LiveSessionSummary summary = live.Run(nullptr);
  const io::ModuleStatus& end = summary.status;
  EXPECT_EQ(testing::CheckBusStatus(live, fed), "");
  EXPECT_GT(2 * end.frames_used, live.subscriber().depth_received());
  std::printf(
      "fed %lld messages (%lld damaged); bad_claw_name %lld, out_of_limits %lld, "
      "claw_unloadable %lld, decode errors %lld; %lld frames fused\n",
      static_cast<long long>(fed), static_cast<long long>(damaged),
      static_cast<long long>(end.bad_messages[io::MessageError::kBadClawName]),
      static_cast<long long>(end.bad_messages[io::MessageError::kOutOfLimits]),
      static_cast<long long>(end.bad_messages[io::MessageError::kClawUnloadable]),
      static_cast<long long>(end.decode_errors), static_cast<long long>(end.frames_used));
}

}  // namespace
}  // namespace graspfill::rt
