// SPDX-License-Identifier: BSD-3-Clause
// The progress line's text (rt/cli/progress.hpp): counts, rate, time left.
#include "progress.hpp"

#include <gtest/gtest.h>

namespace graspfill::cli {
namespace {

TEST(ProgressTest, DoneTotalRateAndTimeLeft) {
  // 120 of 900 frames in 4 s: 30 frames/s, 780 frames to go = 26 s.
  EXPECT_EQ(FormatProgress("replay", "frames", 120, 900, 4.0),
            "replay: 120/900 frames (13%), 30.0 frames/s, 26 s left");
  // Over a minute left: minutes and seconds.
  EXPECT_EQ(FormatProgress("synth", "frames", 10, 1000, 5.0),
            "synth: 10/1000 frames (1%), 2.0 frames/s, 8 min 15 s left");
}

TEST(ProgressTest, NothingToMeasureYet) {
  EXPECT_EQ(FormatProgress("bench", "cases", 0, 12, 0.0), "bench: 0/12 cases (0%)");
  EXPECT_EQ(FormatProgress("bench", "cases", 12, 12, 3.0), "bench: 12/12 cases (100%), 4.0 cases/s");
  EXPECT_EQ(FormatProgress("replay", "frames", 7, 0, 1.0), "replay: 7 frames, 7.0 frames/s");
  // A count past its total (bench: a log's unposed frames) stops at it.
  EXPECT_EQ(FormatProgress("bench", "frames", 130, 120, 2.0), "bench: 120/120 frames (100%), 60.0 frames/s");
}

// Under ctest stderr is no terminal: the line is never drawn.
TEST(ProgressTest, OffWhenStderrIsNoTerminal) {
  if (isatty(STDERR_FILENO) == 1) GTEST_SKIP() << "run with stderr on a terminal";
  EXPECT_FALSE(ProgressWanted());
  ProgressLine line("test", "items", 3);
  EXPECT_FALSE(line.enabled());
  ::testing::internal::CaptureStderr();
  line.Update(1);
  line.Clear();
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace graspfill::cli
