// SPDX-License-Identifier: BSD-3-Clause
// How the CLI meets a user who slips (issue 38): a mistyped option or
// command gets the nearest real one, every product command's --help ends
// with an example, and `live` without a camera says how to run without one.
#include <gtest/gtest.h>

#include <string>

#include "cli_runner.hpp"

namespace graspfill {
namespace {

using testing::RunCli;

TEST(CliManners, AMistypedOptionOrCommandGetsTheNearestOne) {
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"repair in.ply -o out.ply --forse", "bad option '--forse' (did you mean --force?)"},
      {"synth --shape cylinder --sead 3 -o x", "bad option '--sead' (did you mean --seed?)"},
      {"live --depth-from-lmc", "bad option '--depth-from-lmc' (did you mean --depth-from-lcm?)"},
      {"claw parallel -o x.ply --openning 0.05", "bad option '--openning' (did you mean --opening?)"},
      {"eval a.ply b.ply --jsno", "bad option '--jsno' (did you mean --json?)"},
      {"replay x.lcmlog -o x.ply --no-publsh", "bad option '--no-publsh' (did you mean --no-publish?)"},
      {"replai x.lcmlog", "unknown command 'replai' (did you mean replay?)"},
  };
  for (const Case& c : cases) {
    const auto run = RunCli(c.args);
    EXPECT_EQ(run.exit_code, 2) << c.args << "\n" << run.output;
    EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.args << "\n" << run.output;
  }
  // Nothing near: no guess.
  const auto far = RunCli("repair in.ply -o out.ply --zzzzzz");
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_EQ(far.output.find("did you mean"), std::string::npos) << far.output;
}

TEST(CliManners, EveryProductCommandsHelpEndsWithAnExample) {
  for (const char* command :
       {"repair", "replay", "synth", "live", "claw", "config", "view", "eval", "oni-record"}) {
    const auto run = RunCli(std::string(command) + " --help");
    EXPECT_EQ(run.exit_code, 0) << command;
    const size_t at = run.output.find("example: graspfill " + std::string(command) + " ");
    EXPECT_NE(at, std::string::npos) << command << "\n" << run.output;
  }
}

// No camera is attached to the machines the suite runs on; where one is,
// there is nothing to check.
TEST(CliManners, LiveWithoutACameraSaysHowToFeedItFromLcm) {
  const auto run = RunCli("live --lcm-url memq:// --duration-s 0.1");
  if (run.exit_code == 0) GTEST_SKIP() << "a camera is attached";
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("OpenNI2: cannot open"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("graspfill live --depth-from-lcm"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("GRASPFILL_DEPTH"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace graspfill
