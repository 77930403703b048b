// SPDX-License-Identifier: BSD-3-Clause
// synth -> replay -> eval for every built-in shape: the fused cloud lies on
// the true surface, holds no claw, and misses only what the claw covered
// and the top the camera never sees. Replay also repairs; these checks are
// about the fusion and read the observed points only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <string>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "eval/metrics.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill {
namespace {

using testing::ObservedPoints;
using testing::RunCli;
using testing::SampleSurface;
using testing::ScratchDir;

struct Case {
  std::string shape;
  std::string claw;
  std::string grasp;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.shape << "/" << c.claw << "/" << c.grasp; }

class ShapesE2E : public ::testing::TestWithParam<Case> {};

TEST_P(ShapesE2E, CloudIsOnSurfaceClawFreeAndMissesOnlyClawAndTop) {
  const Case& c = GetParam();
  const std::string dir = ScratchDir("e2e_" + c.shape + "_" + c.claw + "_" + c.grasp);
  const auto synth = RunCli("synth --shape " + c.shape + " --claw " + c.claw + " --grasp " + c.grasp +
                            " --seed 7 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/cloud.ply --claw " + c.claw +
                             " --lcm-url memq://");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;

  const ObjectCloud replayed = io::ReadCloudPly(dir + "/cloud.ply");
  const std::vector<Eigen::Vector3f> fused = ObservedPoints(replayed);
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  const TriangleMesh claw = io::ReadMesh(dir + "/claw.ply");
  ASSERT_GT(fused.size(), 1000u);
  RecordProperty("points_added", static_cast<int>(replayed.size() - fused.size()));

  // On the true surface: 95th percentile under 2 mm, < 0.5% beyond 3 mm.
  const std::vector<double> to_gt = mesh::NearestDistances(fused, gt.points_G);
  EXPECT_LT(Percentile(to_gt, 95.0), 0.002);
  EXPECT_LT(1.0 - eval::FractionWithin(to_gt, 0.003), 0.005);

  // No claw left: < 0.1% of points within 2 mm of the claw and > 2 mm from
  // the object.
  const std::vector<Eigen::Vector3f> claw_points = SampleSurface(claw, 0.001f);
  const std::vector<double> to_claw = mesh::NearestDistances(fused, claw_points);
  int claw_left = 0;
  for (size_t i = 0; i < fused.size(); ++i) claw_left += to_claw[i] < 0.002 && to_gt[i] > 0.002;
  EXPECT_LT(claw_left, 0.001 * fused.size()) << claw_left << " claw points";

  // Coverage: a true-surface point farther than 3 mm from the cloud must be
  // where the claw was (within 15 mm of it: a finger also shadows its
  // surroundings at grazing views) or in the top band facing the palm.
  const std::vector<double> gt_to_cloud = mesh::NearestDistances(gt.points_G, fused);
  const std::vector<double> gt_to_claw = mesh::NearestDistances(gt.points_G, claw_points);
  float top_z = 1e9f, bottom_z = -1e9f;
  for (const Eigen::Vector3f& p : gt.points_G) {
    top_z = std::min(top_z, p.z());
    bottom_z = std::max(bottom_z, p.z());
  }
  const float top_band_z = top_z + 0.15f * (bottom_z - top_z);
  int unexplained = 0;
  for (size_t i = 0; i < gt.size(); ++i) {
    if (gt_to_cloud[i] <= 0.003) continue;
    if (gt_to_claw[i] < 0.015 || gt.points_G[i].z() < top_band_z) continue;
    ++unexplained;
  }
  EXPECT_LT(unexplained, 0.01 * gt.size())
      << unexplained << " of " << gt.size() << " ground-truth points missed elsewhere";

  // The repair: never worse than the fused cloud, and where the fused cloud
  // misses a lot (the top, the claw holes: chamfer above 3 mm^2) it closes
  // most of the gap (measured 0.05-0.14 of the fused chamfer at seed 7).
  const eval::CloudMetrics before = eval::Compare(fused, gt.points_G);
  const eval::CloudMetrics after = eval::Compare(replayed.points_G, gt.points_G);
  RecordProperty("chamfer_fused_mm2", std::to_string(before.chamfer_mm2));
  RecordProperty("chamfer_repaired_mm2", std::to_string(after.chamfer_mm2));
  std::printf("%s/%s/%s: chamfer fused %.2f -> repaired %.2f mm^2 (+%zu points)\n", c.shape.c_str(),
              c.claw.c_str(), c.grasp.c_str(), before.chamfer_mm2, after.chamfer_mm2,
              replayed.size() - fused.size());
  EXPECT_LE(after.chamfer_mm2, before.chamfer_mm2 + 1e-9);
  if (before.chamfer_mm2 > 3.0) {
    EXPECT_LT(after.chamfer_mm2, 0.25 * before.chamfer_mm2);
  }
}

INSTANTIATE_TEST_SUITE_P(AllShapes, ShapesE2E,
                         ::testing::Values(Case{"cuboid", "three-finger", "top-straight"},
                                           Case{"triangular-prism", "three-finger", "top-straight"},
                                           Case{"cylinder", "three-finger", "top-straight"},
                                           Case{"sphere", "three-finger", "top-straight"},
                                           Case{"elliptic-cylinder", "parallel", "top-straight"},
                                           Case{"ellipsoid", "three-finger", "top-straight"},
                                           Case{"cuboid", "parallel", "middle-straight"},
                                           Case{"cylinder", "three-finger", "top-oblique"}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string name =
                               info.param.shape + "_" + info.param.claw + "_" + info.param.grasp;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace graspfill
