// SPDX-License-Identifier: BSD-3-Clause
// `graspfill bench` through the real CLI on the bundled recording: Open3D's
// integrators side by side on the frames the pipeline fused (issue 39, the
// integrator), their rows consistent with the reference column, and the
// tensor VoxelBlockGrid's final cloud as good as the product's against the
// recording's truth.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"

namespace graspfill {
namespace {

using testing::RunCli;

TEST(BenchIntegrators, SideBySideOnTheFusedFrames) {
  const auto r = RunCli("bench --repeat 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  const auto& reference = json["open3d_same_frames"];
  const auto& section = json["integrators_same_frames"];
  const auto& rows = section["integrators"];
  ASSERT_EQ(rows.size(), 4u) << section.dump(1);
  EXPECT_EQ(rows[0]["name"], "ScalableTSDFVolume 16^3");  // the product's
  EXPECT_EQ(rows[3]["name"], "VoxelBlockGrid 8^3");
  EXPECT_FALSE(rows[0].contains("threads_2"));  // only with --two-threads
  // The reference column is the product's row, from the same run.
  EXPECT_EQ(rows[0]["threads_1"]["integrate_ms"].get<double>(), reference["integrate_ms"].get<double>());
  const int frames = reference["frames"].get<int>();
  ASSERT_GT(frames, 10);

  const auto& product = rows[0];
  const double voxel_mm = 1.5;  // TsdfConfig's
  for (const auto& row : rows) {
    SCOPED_TRACE(row.dump());
    EXPECT_EQ(row["frames"].get<int>(), frames);
    EXPECT_GT(row["threads_1"]["integrate_ms"].get<double>(), 0.0);
    EXPECT_GT(row["threads_1"]["extract_ms"]["p50"].get<double>(), 0.0);
    EXPECT_NEAR(row["points"].get<double>(), product["points"].get<double>(),
                0.1 * product["points"].get<double>());
    // The model: the same share of the truth covered (within a point in a
    // hundred) and as close to it (within a tenth of a voxel) as the
    // product's cloud.
    EXPECT_NEAR(row["truth_coverage_2mm"].get<double>(), product["truth_coverage_2mm"].get<double>(), 0.01);
    EXPECT_NEAR(row["truth_p95_mm"].get<double>(), product["truth_p95_mm"].get<double>(), 0.1 * voxel_mm);
    if (row == product) continue;
    // Another grid samples the surface elsewhere: about a voxel apart.
    EXPECT_LT(row["to_product_mm"]["p95"].get<double>(), voxel_mm);
    EXPECT_LT(row["from_product_mm"]["p95"].get<double>(), voxel_mm);
  }
  EXPECT_GT(product["truth_coverage_2mm"].get<double>(), 0.5);
}

}  // namespace
}  // namespace graspfill
