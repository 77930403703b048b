// SPDX-License-Identifier: BSD-3-Clause
// The benchmark's Poisson-only baseline (src/repair/poisson_baseline.hpp):
// one Poisson surface of the whole protocol cloud fills its holes, nothing
// lands where the cloud already is, and bad input is refused.
#include "poisson_baseline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>

#include "eval/metrics.hpp"
#include "fill_checks.hpp"
#include "graspfill/mesh/nearest_distances.hpp"
#include "synth/paper_protocol.hpp"

namespace graspfill::repair {
namespace {

TEST(PoissonBaseline, DefaultsValidateAndBadValuesThrow) {
  EXPECT_NO_THROW(PoissonFillConfig{}.Validate());
  PoissonFillConfig p;
  p.density_trim_quantile = 1.0;
  EXPECT_THROW(p.Validate(), std::invalid_argument);
  p = {};
  p.poisson_depth = 1;
  EXPECT_THROW(p.Validate(), std::invalid_argument);
}

TEST(PoissonBaseline, BadInputThrowsAndTinyInputIsANoOp) {
  PointList points = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)};
  EXPECT_TRUE(PoissonFillAll(points, PoissonFillConfig{}).empty());
  PointList bad = points;
  bad[1].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(PoissonFillAll(bad, PoissonFillConfig{}), std::invalid_argument);
  const std::vector<Eigen::Vector3f> normals(2, Eigen::Vector3f::UnitZ());
  EXPECT_THROW(PoissonFillAll(points, PoissonFillConfig{}, &normals), std::invalid_argument);
}

TEST(PoissonBaseline, FillsEveryHoleOfTheProtocolCylinder) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.grasp = synth::GraspWay::kTopStraight;
  config.random_pose = false;
  config.num_points = 50000;
  const synth::PaperProtocolCloud cloud = synth::MakePaperProtocolCloud(config);
  const NeighborIndex index(cloud.holey);
  const PointList added = PoissonFillAll(cloud.holey, PoissonFillConfig{}, nullptr, &index);
  PointList repaired = cloud.holey;
  repaired.insert(repaired.end(), added.begin(), added.end());
  const eval::CloudMetrics before = eval::Compare(cloud.holey, cloud.ground_truth);
  const eval::CloudMetrics after = eval::Compare(repaired, cloud.ground_truth);
  std::printf(
      "[baseline] Poisson-only, cylinder top: +%zu pts; chamfer %.3f -> %.3f mm^2, "
      "gt->pred p95 %.2f -> %.2f mm\n",
      added.size(), before.chamfer_mm2, after.chamfer_mm2, before.p95_gt_to_pred_mm, after.p95_gt_to_pred_mm);
  ASSERT_FALSE(added.empty());
  // One smooth surface closes the flat top as a dome, so the whole-cloud
  // chamfer drops by only ~40% (26.2 -> 16.0 mm^2 when written).
  EXPECT_LT(after.chamfer_mm2, 0.75 * before.chamfer_mm2);
  EXPECT_LT(after.p95_gt_to_pred_mm, before.p95_gt_to_pred_mm);
  // Nothing where the cloud already is: every added point keeps the
  // default gap (2 D) to the cloud, up to sampling (half of it asserted).
  const double d = testing::MeanNn(cloud.holey);
  const std::vector<double> to_cloud = mesh::NearestDistances(added, cloud.holey);
  EXPECT_GT(*std::min_element(to_cloud.begin(), to_cloud.end()), 0.5 * 1.9 * d);
  // Deterministic (Open3D's Poisson with one thread).
  EXPECT_TRUE(added == PoissonFillAll(cloud.holey, PoissonFillConfig{}, nullptr, &index));
}

}  // namespace
}  // namespace graspfill::repair
