// SPDX-License-Identifier: BSD-3-Clause
// Grasp after grasp through the real CLI: `synth --grasps` writes one
// session of three grasps of three different objects; `replay` gives three
// final models, each on its own object (p95 within 2 mm) and with nothing
// of the object before it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill::testing {
namespace {

constexpr double kP95M = 0.002;      // the bound: p95 within 2 mm
constexpr double kStrayM = 0.004;    // a point this far from its own object...
constexpr double kOnOtherM = 0.001;  // ...and this close to the one before is a leftover

TEST(GraspsE2E, ThreeGraspsGiveThreeModelsEachOfItsOwnObject) {
  const std::string dir = ScratchDir("e2e_grasps");
  const auto synth = RunCli("synth --grasps cuboid,cylinder,sphere --frames 16 --seed 5 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto replay =
      RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/model.ply --json --lcm-url memq://");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const nlohmann::json report = nlohmann::json::parse(replay.output.substr(replay.output.find('{')));
  ASSERT_EQ(report["grasps"].size(), 3u) << report.dump(2);

  std::vector<std::vector<Eigen::Vector3f>> truths;
  for (int k = 1; k <= 3; ++k) {
    truths.push_back(io::ReadCloudPly(dir + "/grasp" + std::to_string(k) + "/gt_cloud.ply").points_G);
  }
  for (int k = 1; k <= 3; ++k) {
    const nlohmann::json& g = report["grasps"][k - 1];
    EXPECT_EQ(g["grasp_id"].get<int>(), k);
    const std::string path = g["output"].get<std::string>();
    EXPECT_EQ(path, k == 3 ? dir + "/model.ply" : dir + "/model.grasp" + std::to_string(k) + ".ply");
    const std::vector<Eigen::Vector3f> model = io::ReadCloudPly(path).points_G;
    ASSERT_GT(model.size(), 1000u) << path;
    const std::vector<double> to_own = mesh::NearestDistances(model, truths[k - 1]);
    const double p95 = Percentile(to_own, 95.0);
    EXPECT_LT(p95, kP95M) << "grasp " << k;
    RecordProperty("p95_mm_grasp" + std::to_string(k), std::to_string(1000.0 * p95));
    if (k == 1) continue;
    // Nothing of the previous object: no point far from this object that
    // lies on the one before.
    const std::vector<double> to_previous = mesh::NearestDistances(model, truths[k - 2]);
    int leftovers = 0;
    for (size_t i = 0; i < model.size(); ++i) {
      leftovers += to_own[i] > kStrayM && to_previous[i] < kOnOtherM;
    }
    EXPECT_EQ(leftovers, 0) << "grasp " << k;
  }
}

}  // namespace
}  // namespace graspfill::testing
