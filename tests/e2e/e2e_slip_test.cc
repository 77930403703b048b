// The object slipping in the grasp (issue 9, synth --slip-mm): what a slip
// does to the fused model when nothing corrects it. The frames before the
// slip fuse the object where it was grasped, those after it where it slid
// to. A slide shorter than the TSDF's truncation (6 mm) does not double the
// surface: the volume averages the two positions, weighted by the frames
// on either side, into one surface between them; a longer one does.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "graspfill/eval/metrics.hpp"
#include "graspfill/io/ply.hpp"

namespace graspfill {
namespace {

using testing::ObservedPoints;
using testing::RunCli;
using testing::ScratchDir;

// A fused point is on the surface as grasped when within kOnM of that truth
// and off the one after the slip by over kOffM (and the other way round).
constexpr double kOnM = 0.00075;
constexpr double kOffM = 0.0015;

struct SlipFused {
  double p95_after_m{0.0};   ///< to the truth after the slip (gt_cloud.ply)
  double p95_before_m{0.0};  ///< to the truth as grasped (gt_cloud_before_slip.ply)
  double old_share{0.0};     ///< on the surface as grasped, off the one after
  double new_share{0.0};     ///< on the surface after, off the one as grasped
  size_t points{0};
  nlohmann::json report;
};

// Replays DIR's recording without repair and measures the fused points
// against both truths (the one before the slip: DIR/gt_cloud_before_slip.ply,
// or gt_cloud.ply for a recording without slip).
SlipFused ReplayAndMeasure(const std::string& dir, const std::string& extra = "") {
  SlipFused f;
  const std::string cloud = dir + "/cloud" + extra + ".ply";
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + cloud +
                             " --force --json --no-publish --no-repair " + extra);
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  if (replay.exit_code != 0) return f;
  f.report = nlohmann::json::parse(replay.output.substr(replay.output.find('{')));
  const std::vector<Eigen::Vector3f> fused = ObservedPoints(io::ReadCloudPly(cloud));
  const std::string before_path = std::ifstream(dir + "/gt_cloud_before_slip.ply").good()
                                      ? dir + "/gt_cloud_before_slip.ply"
                                      : dir + "/gt_cloud.ply";
  const std::vector<double> to_after =
      eval::NearestDistances(fused, io::ReadCloudPly(dir + "/gt_cloud.ply").points_G);
  const std::vector<double> to_before =
      eval::NearestDistances(fused, io::ReadCloudPly(before_path).points_G);
  f.points = fused.size();
  if (fused.empty()) return f;
  f.p95_after_m = eval::Percentile(to_after, 95.0);
  f.p95_before_m = eval::Percentile(to_before, 95.0);
  size_t old_points = 0, new_points = 0;
  for (size_t i = 0; i < fused.size(); ++i) {
    old_points += to_before[i] <= kOnM && to_after[i] > kOffM;
    new_points += to_after[i] <= kOnM && to_before[i] > kOffM;
  }
  f.old_share = static_cast<double>(old_points) / fused.size();
  f.new_share = static_cast<double>(new_points) / fused.size();
  return f;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Uncorrected, a 3 mm slip leaves the bottom of a cylinder off the truth
// after the slip by more than 1.5 mm at p95: seen before and after, the
// bottom is fused as a blend of both positions.
TEST(SlipE2E, AnUncorrectedSlipMovesTheModelOffTheTruth) {
  const std::string dir = ScratchDir("e2e_slip_uncorrected");
  const auto synth = RunCli("synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 "
                            "--seed 2 --slip-mm 3 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const nlohmann::json slip = ReadJson(dir + "/scene.json")["slip"];
  const int moved = slip["first_frame_moved"].get<int>();
  const int settled = slip["first_frame_settled"].get<int>();
  // The premise: many frames on either side of the slide.
  ASSERT_GE(moved, 15);
  ASSERT_LE(settled, 50);
  const SlipFused f = ReplayAndMeasure(dir);
  ASSERT_GT(f.points, 2000u);
  std::printf("uncorrected 3 mm slip: p95 %.2f mm to the truth after, %.2f mm before; "
              "%.1f %% of the points on the old surface only, %.1f %% on the new only\n",
              1000 * f.p95_after_m, 1000 * f.p95_before_m, 100 * f.old_share, 100 * f.new_share);
  EXPECT_GT(f.p95_after_m, 0.0015);
  EXPECT_GT(f.old_share, 0.05);
  // Without the slip, the same recording's frames meet the truth.
  const std::string still = ScratchDir("e2e_slip_still");
  ASSERT_EQ(RunCli("synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 --seed 2 -o " +
                   still).exit_code, 0);
  const SlipFused f0 = ReplayAndMeasure(still);
  EXPECT_LT(f0.p95_after_m, 0.001);
  EXPECT_LT(f0.old_share + f0.new_share, 0.001);
}

// The README's table ("Imperfect robots", slip): three shapes, both claws,
// 90 frames, no slip vs an uncorrected 3 mm slip (SLIP_TABLE_MM=S for
// another), fused points only (no repair). Minutes, so not in the suite:
//   build/bin/e2e_slip_test --gtest_also_run_disabled_tests --gtest_filter='*Table*'
TEST(SlipE2E, DISABLED_Table) {
  const char* mm_env = std::getenv("SLIP_TABLE_MM");
  const std::string mm = mm_env ? mm_env : "3";
  const char* cases[][2] = {{"cuboid", "three-finger"}, {"cuboid", "parallel"},
                            {"cylinder", "three-finger"}, {"cylinder", "parallel"},
                            {"sphere", "three-finger"}, {"sphere", "parallel"}};
  std::printf("| shape, claw | slip direction in G, frames moved..settled | p95 mm, no slip | "
              "p95 mm to the truth after / before the slip | points on the old surface only / "
              "the new only |\n|---|---|---|---|---|\n");
  for (const auto& c : cases) {
    const std::string name = std::string(c[0]) + "_" + c[1];
    const std::string clean = ScratchDir("slip_table_clean_" + name);
    const std::string slipped = ScratchDir("slip_table_slip_" + name);
    const std::string common = std::string("synth --shape ") + c[0] + " --claw " + c[1] + " --seed 11 ";
    ASSERT_EQ(RunCli(common + "-o " + clean).exit_code, 0);
    ASSERT_EQ(RunCli(common + "--slip-mm " + mm + " -o " + slipped).exit_code, 0);
    const nlohmann::json slip = ReadJson(slipped + "/scene.json")["slip"];
    const SlipFused f0 = ReplayAndMeasure(clean);
    const SlipFused f1 = ReplayAndMeasure(slipped);
    std::printf("| %s, %s | [%.2f %.2f %.2f], %d..%d | %.2f | %.2f / %.2f | %.1f %% / %.1f %% |\n",
                c[0], c[1], slip["direction_G"][0].get<double>(),
                slip["direction_G"][1].get<double>(), slip["direction_G"][2].get<double>(),
                slip["first_frame_moved"].get<int>(), slip["first_frame_settled"].get<int>(),
                1000 * f0.p95_after_m, 1000 * f1.p95_after_m, 1000 * f1.p95_before_m,
                100 * f1.old_share, 100 * f1.new_share);
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace graspfill
