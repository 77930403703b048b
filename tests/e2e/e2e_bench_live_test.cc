// SPDX-License-Identifier: BSD-3-Clause
// `graspfill bench live` through the real CLI on the bundled recording: the
// runs it reports, in-process and (where a network namespace can be made)
// across processes over UDP multicast, hold together.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"

namespace graspfill {
namespace {

using testing::RunCli;

void CheckRun(const nlohmann::json& run, int frames) {
  SCOPED_TRACE(run.dump());
  ASSERT_FALSE(run.contains("skipped"));
  // The module's count against the bench's reading of the log: nothing
  // lost on the way in.
  EXPECT_EQ(run["frames_in"].get<int>(), frames);
  EXPECT_GT(run["frames_used"].get<int>(), 0);
  EXPECT_LE(run["frames_used"].get<int>() + run["frames_dropped"].get<int>(), frames);
  EXPECT_GE(run["clouds"].get<int>(), 1);
  const auto& lat = run["latency_ms"];
  EXPECT_GT(lat["p50"].get<double>(), 0.0);
  EXPECT_LE(lat["p50"].get<double>(), lat["p95"].get<double>());
  EXPECT_LE(lat["p95"].get<double>(), lat["p99"].get<double>());
  EXPECT_LE(lat["p99"].get<double>(), lat["max"].get<double>());
  EXPECT_GT(run["full_repair_ms"]["p50"].get<double>(), 0.0);  // at least the final's
  EXPECT_GT(run["rss_mb"]["start"].get<double>(), 10.0);
  EXPECT_GT(run["rss_mb"]["end"].get<double>(), 10.0);
}

TEST(BenchLive, ReportsEveryRunItWasAskedFor) {
  // 1x: at 4x a loaded machine may fuse too few of the 36 frames for a cloud.
  const auto r = RunCli("bench live --speeds 1 --transport both --repair both --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  const int frames = json["depth_frames"].get<int>();
  ASSERT_GT(frames, 10);
  ASSERT_EQ(json["runs"].size(), 4u);
  for (const auto& run : json["runs"]) {
    EXPECT_EQ(run["speed"].get<double>(), 1.0);
    const bool udpm = run["transport"] == "udpm";
    if (udpm && run.contains("skipped")) {
      // Only for want of a private network namespace (never the host's network).
      EXPECT_NE(run["skipped"].get<std::string>().find("network namespace"), std::string::npos);
      continue;
    }
    CheckRun(run, frames);
    if (run["repair"] == "full") {
      EXPECT_EQ(run["update_ms"]["p50"].get<double>(), 0.0);
    }
  }
}

// The fault soak (issue 36), short: `live` over the bus with 2% malformed
// messages of every kind among the valid ones lives to the end, counts
// each under the reason it was sent for, keeps its RSS near the clean
// run's and keeps publishing clouds (in 9 of the run's 10 windows of 2 s
// at least: a loaded CI machine may stall the player for a second).
TEST(BenchLive, FaultSoakCountsEveryRejectAndKeepsPublishing) {
  const auto r = RunCli(
      "bench live --speeds 1 --transport memq --repair incremental --soak-s 20 --soak-faults 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  ASSERT_EQ(json["runs"].size(), 3u);
  const auto& clean = json["runs"][1];
  const auto& faulted = json["runs"][2];
  if (clean.contains("skipped")) {
    EXPECT_NE(clean["skipped"].get<std::string>().find("network namespace"), std::string::npos);
    GTEST_SKIP() << "no private network namespace";
  }
  SCOPED_TRACE(faulted.dump());
  EXPECT_EQ(clean["fault_percent"].get<double>(), 0.0);
  EXPECT_EQ(faulted["fault_percent"].get<double>(), 2.0);
  EXPECT_EQ(clean["malformed_sent"].get<int>(), 0);
  EXPECT_EQ(clean["rejects_counted"].get<int>(), 0) << clean.dump();  // the loop itself is valid
  ASSERT_FALSE(faulted.contains("skipped"));
  EXPECT_TRUE(clean["live_alive_at_end"].get<bool>());
  EXPECT_TRUE(faulted["live_alive_at_end"].get<bool>());
  // Every kind of defect sent at least once (19 in the cycle).
  EXPECT_GE(faulted["malformed_sent"].get<int>(), 19);
  // Every malformed message that arrived is counted under its reason. The
  // kernel drops datagrams when the socket's buffer is full (a loaded
  // machine, frames of 200 kB at 4x): then valid frames are missing too,
  // and the counts may fall short of what was sent, never exceed it.
  const auto& sent = faulted["malformed_sent_by_reason"];
  const auto& counted = faulted["rejects_counted_by_reason"];
  if (faulted["frames_in"] == faulted["frames_sent"]) {
    EXPECT_EQ(faulted["rejects_counted"], faulted["malformed_sent"]);
    EXPECT_EQ(counted, sent);
  } else {
    EXPECT_LE(faulted["rejects_counted"].get<int>(), faulted["malformed_sent"].get<int>());
    for (auto it = counted.begin(); it != counted.end(); ++it) {
      ASSERT_TRUE(sent.contains(it.key())) << it.key() << " counted, none sent";
      EXPECT_LE(it.value().get<int>(), sent[it.key()].get<int>()) << it.key();
    }
    EXPECT_GT(faulted["rejects_counted"].get<int>(), 0);
  }
  for (const char* reason : {"malformed", "bad_size", "bad_intrinsics", "bad_depth_scale", "bad_encoding",
                             "bad_pose", "bad_value", "bad_timestamp", "bad_claw_name", "out_of_limits"}) {
    EXPECT_TRUE(faulted["malformed_sent_by_reason"].contains(reason)) << reason;
  }
  EXPECT_LE(faulted["rss_mb"]["peak"].get<double>(), 1.1 * clean["rss_mb"]["peak"].get<double>());
  EXPECT_GE(faulted["frames_used"].get<int>(), 10);
  ASSERT_GE(faulted["clouds_per_window"].size(), 9u);
  int windows_with_clouds = 0;
  for (const auto& n : faulted["clouds_per_window"]) windows_with_clouds += n.get<int>() > 0;
  EXPECT_GE(windows_with_clouds, static_cast<int>(faulted["clouds_per_window"].size()) - 1);
}

TEST(BenchLive, BadOptionsAreUsageErrors) {
  for (const char* args :
       {"--speeds 0", "--speeds x", "--transport tcp", "--repair some", "--publish-every 0", "--soak-s 5",
        "--soak-s 30", "--soak-faults 1", "--soak-s 60 --soak-faults 0", "--soak-s 60 --soak-faults 80",
        "--soak-s 60 --soak-faults 1 --soak-speed 0", "--bogus"}) {
    const auto r = RunCli(std::string("bench live ") + args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("usage: graspfill bench live"), std::string::npos) << args;
  }
  const auto missing = RunCli("bench live /nonexistent/log.lcmlog --transport memq");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("/nonexistent/log.lcmlog"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace graspfill
