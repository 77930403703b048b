// SPDX-License-Identifier: BSD-3-Clause
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
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

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
  /// With --track-object: the fused points moved to where the tracker says
  /// the object is now (track_object.object_pose), to the truth after.
  double p95_tracked_pose_m{0.0};
  Eigen::Vector3d shift_found_m{0.0, 0.0, 0.0};
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
      mesh::NearestDistances(fused, io::ReadCloudPly(dir + "/gt_cloud.ply").points_G);
  const std::vector<double> to_before = mesh::NearestDistances(fused, io::ReadCloudPly(before_path).points_G);
  f.points = fused.size();
  if (fused.empty()) return f;
  f.p95_after_m = Percentile(to_after, 95.0);
  f.p95_before_m = Percentile(to_before, 95.0);
  size_t old_points = 0, new_points = 0;
  for (size_t i = 0; i < fused.size(); ++i) {
    old_points += to_before[i] <= kOnM && to_after[i] > kOffM;
    new_points += to_after[i] <= kOnM && to_before[i] > kOffM;
  }
  f.old_share = static_cast<double>(old_points) / fused.size();
  f.new_share = static_cast<double>(new_points) / fused.size();
  const nlohmann::json& track = f.report["track_object"];
  if (track["enabled"].get<bool>()) {
    Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) S.matrix()(r, c) = track["object_pose"]["S_G"][r][c].get<double>();
    }
    f.shift_found_m = S.translation();
    std::vector<Eigen::Vector3f> moved;
    for (const Eigen::Vector3f& p : fused) moved.push_back((S * p.cast<double>()).cast<float>());
    f.p95_tracked_pose_m =
        Percentile(mesh::NearestDistances(moved, io::ReadCloudPly(dir + "/gt_cloud.ply").points_G), 95.0);
  }
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
  const auto synth = RunCli(
      "synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 "
      "--seed 2 --slip-mm 3 -o " +
      dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const nlohmann::json slip = ReadJson(dir + "/scene.json")["slip"];
  const int moved = slip["first_frame_moved"].get<int>();
  const int settled = slip["first_frame_settled"].get<int>();
  // The premise: many frames on either side of the slide.
  ASSERT_GE(moved, 15);
  ASSERT_LE(settled, 50);
  const SlipFused f = ReplayAndMeasure(dir);
  ASSERT_GT(f.points, 2000u);
  std::printf(
      "uncorrected 3 mm slip: p95 %.2f mm to the truth after, %.2f mm before; "
      "%.1f %% of the points on the old surface only, %.1f %% on the new only\n",
      1000 * f.p95_after_m, 1000 * f.p95_before_m, 100 * f.old_share, 100 * f.new_share);
  EXPECT_GT(f.p95_after_m, 0.0015);
  EXPECT_GT(f.old_share, 0.05);
  // Without the slip, the same recording's frames meet the truth.
  const std::string still = ScratchDir("e2e_slip_still");
  ASSERT_EQ(RunCli("synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 --seed 2 -o " + still)
                .exit_code,
            0);
  const SlipFused f0 = ReplayAndMeasure(still);
  EXPECT_LT(f0.p95_after_m, 0.001);
  EXPECT_LT(f0.old_share + f0.new_share, 0.001);
}

Eigen::Vector3d Vec3(const nlohmann::json& j) {
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

// replay --track-object: the frames after the slip are fused where the
// object was first seen, so the model stays on the truth as grasped, and
// the object's pose found puts it on the truth after the slip (within the
// 1.5 mm the issue asks for at p95). Without a slip it changes the model's
// p95 by less than 0.1 mm.
TEST(SlipE2E, TrackingKeepsTheModelOnTheObject) {
  const std::string dir = ScratchDir("e2e_slip_tracked");
  const std::string common = "synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 --seed 2 ";
  ASSERT_EQ(RunCli(common + "--slip-mm 3 -o " + dir).exit_code, 0);
  const nlohmann::json slip = ReadJson(dir + "/scene.json")["slip"];
  const SlipFused plain = ReplayAndMeasure(dir);
  const SlipFused tracked = ReplayAndMeasure(dir, "--track-object");
  ASSERT_GT(tracked.points, 2000u);
  const Eigen::Vector3d d = Vec3(slip["displacement_G_m"]);
  std::printf(
      "3 mm slip, tracked: p95 %.2f mm to the truth as grasped (uncorrected %.2f), %.2f mm "
      "at the pose found to the truth after (uncorrected %.2f); shift found %.2f %.2f %.2f "
      "mm, true %.2f %.2f %.2f mm\n",
      1000 * tracked.p95_before_m, 1000 * plain.p95_before_m, 1000 * tracked.p95_tracked_pose_m,
      1000 * plain.p95_after_m, 1000 * tracked.shift_found_m.x(), 1000 * tracked.shift_found_m.y(),
      1000 * tracked.shift_found_m.z(), 1000 * d.x(), 1000 * d.y(), 1000 * d.z());
  EXPECT_LE(tracked.p95_before_m, 0.0015);
  // The target: the model after the slip, where the object is.
  EXPECT_LE(tracked.p95_tracked_pose_m, 0.0015);
  EXPECT_GT(plain.p95_after_m, 0.0015);  // the same, uncorrected
  EXPECT_LT((tracked.shift_found_m - d).norm(), 0.001);
  const nlohmann::json& t = tracked.report["track_object"];
  EXPECT_GE(t["frames_tracked"].get<int>(), 45);
  EXPECT_EQ(t["frames_rejected"]["total"].get<int>(), 0);
  EXPECT_EQ(tracked.report["frames_used"].get<int>(),
            t["frames_tracked"].get<int>() + t["frames_before_a_model"].get<int>());
  EXPECT_FALSE(plain.report["track_object"]["enabled"].get<bool>());

  const std::string still = ScratchDir("e2e_slip_tracked_still");
  ASSERT_EQ(RunCli(common + "-o " + still).exit_code, 0);
  const SlipFused still_plain = ReplayAndMeasure(still);
  const SlipFused still_tracked = ReplayAndMeasure(still, "--track-object");
  EXPECT_NEAR(still_tracked.p95_after_m, still_plain.p95_after_m, 0.0001);
  EXPECT_LT(still_tracked.shift_found_m.norm(), 0.001);
}

// The slip tables of docs/measurements/2026-12-03-imperfect-robots.md:
// three shapes, both claws, 90 frames, no slip vs an uncorrected 3 mm slip
// (SLIP_TABLE_MM=S for another), fused points only (no repair). Minutes,
// so not in the suite:
//   build/bin/e2e_slip_test --gtest_also_run_disabled_tests --gtest_filter='*Table*'
TEST(SlipE2E, DISABLED_Table) {
  const char* mm_env = std::getenv("SLIP_TABLE_MM");
  const std::string mm = mm_env ? mm_env : "3";
  const char* cases[][2] = {{"cuboid", "three-finger"},   {"cuboid", "parallel"},
                            {"cylinder", "three-finger"}, {"cylinder", "parallel"},
                            {"sphere", "three-finger"},   {"sphere", "parallel"}};
  std::printf(
      "| shape, claw | slip direction in G, frames moved..settled | p95 mm, no slip | "
      "p95 mm to the truth after / before the slip | points on the old surface only / "
      "the new only | tracked: p95 mm to the truth before / after at the pose found, "
      "no slip | shift found - true, mm | tracking ms/frame |\n"
      "|---|---|---|---|---|---|---|---|\n");
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
    const SlipFused t0 = ReplayAndMeasure(clean, "--track-object");
    const SlipFused t1 = ReplayAndMeasure(slipped, "--track-object");
    const Eigen::Vector3d miss = t1.shift_found_m - Vec3(slip["displacement_G_m"]);
    std::printf(
        "| %s, %s | [%.2f %.2f %.2f], %d..%d | %.2f | %.2f / %.2f | %.1f %% / %.1f %% | "
        "**%.2f** / %.2f, %.2f | %.2f %.2f %.2f | %.2f |\n",
        c[0], c[1], slip["direction_G"][0].get<double>(), slip["direction_G"][1].get<double>(),
        slip["direction_G"][2].get<double>(), slip["first_frame_moved"].get<int>(),
        slip["first_frame_settled"].get<int>(), 1000 * f0.p95_after_m, 1000 * f1.p95_after_m,
        1000 * f1.p95_before_m, 100 * f1.old_share, 100 * f1.new_share, 1000 * t1.p95_before_m,
        1000 * t1.p95_tracked_pose_m, 1000 * t0.p95_after_m, 1000 * miss.x(), 1000 * miss.y(),
        1000 * miss.z(), t1.report["track_object"]["ms_per_frame"].get<double>());
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace graspfill
