// SPDX-License-Identifier: BSD-3-Clause
// `graspfill bench` through the real CLI on the bundled recording, its pass
// with the depth 1% long (issue 40, the depth calibration's cost): the
// recording is shorter than the estimate's minimum of fused frames, so the
// pass plays it again until it has them; the scale must then be found and
// applied, and dividing the frames by it timed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"
#include "graspfill/refine/pose_refiner.hpp"

namespace graspfill {
namespace {

using testing::RunCli;

TEST(BenchDepthScale, FindsTheOnePercentAndTimesTheDivision) {
  const auto r = RunCli("bench --repeat 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  const auto& pass = json["depth_1pc_long"];
  SCOPED_TRACE(pass.dump());
  const int frames = json["frames"].get<int>();
  ASSERT_GT(frames, 0);
  // Enough turns for the estimate's minimum, and no more than one past it.
  const int turns = pass["turns"].get<int>();
  EXPECT_GE(turns * frames, refine::kDepthScaleMinFrames);
  EXPECT_LT((turns - 1) * frames, refine::kDepthScaleMinFrames * 5 / 4);
  // Found within the 0.2% the calibration promises, and applied.
  ASSERT_FALSE(pass["stderr"].is_null());
  EXPECT_NEAR(pass["factor_found"].get<double>(), 1.01, 0.002);
  EXPECT_NEAR(pass["applied"].get<double>(), 1.01, 0.002);
  EXPECT_GT(json["graspfill"]["depth_rescale_when_applied_ms"].get<double>(), 0.0);
}

}  // namespace
}  // namespace graspfill
