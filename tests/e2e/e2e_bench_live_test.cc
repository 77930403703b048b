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
    if (run["repair"] == "full") EXPECT_EQ(run["update_ms"]["p50"].get<double>(), 0.0);
  }
}

TEST(BenchLive, BadOptionsAreUsageErrors) {
  for (const char* args : {"--speeds 0", "--speeds x", "--transport tcp", "--repair some",
                           "--publish-every 0", "--soak-s 5", "--bogus"}) {
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
