// SPDX-License-Identifier: BSD-3-Clause
// Imperfect robots (issue 9): recordings whose logged gripper poses carry a
// hand-eye error, per-state noise and a clock offset, replayed with pose
// refinement and without it. Refined, the fused cloud lies on the truth in
// the true G and holds no claw; unrefined, the same frames fuse worse; the
// hand-eye correction found matches the error synth injected.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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

struct Fused {
  double p95_m{0.0};
  int claw_left{0};
  size_t points{0};
  double coverage{0.0};  ///< share of the truth within 2 mm of the whole output
  nlohmann::json report;
};

// Replays DIR's recording (with the repair when `repair`) and measures the
// fused points (and the whole output's coverage) against DIR's ground truth.
Fused ReplayAndMeasure(const std::string& dir, const std::string& extra, bool repair = false) {
  Fused f;
  std::string tag = extra;  // the output's name: the flags, spaces as _
  std::replace(tag.begin(), tag.end(), ' ', '_');
  const std::string cloud = dir + "/cloud" + tag + ".ply";
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + cloud +
                             " --force --json --no-publish " + (repair ? "" : "--no-repair ") + extra);
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  if (replay.exit_code != 0) return f;
  f.report = nlohmann::json::parse(replay.output.substr(replay.output.find('{')));
  const ObjectCloud output = io::ReadCloudPly(cloud);
  const std::vector<Eigen::Vector3f> fused = ObservedPoints(output);
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  const std::vector<Eigen::Vector3f> claw = SampleSurface(io::ReadMesh(dir + "/claw.ply"), 0.001f);
  const std::vector<double> to_gt = mesh::NearestDistances(fused, gt.points_G);
  const std::vector<double> to_claw = mesh::NearestDistances(fused, claw);
  f.p95_m = Percentile(to_gt, 95.0);
  for (size_t i = 0; i < fused.size(); ++i) f.claw_left += to_claw[i] < 0.002 && to_gt[i] > 0.002;
  f.points = fused.size();
  f.coverage = eval::FractionWithin(mesh::NearestDistances(gt.points_G, output.points_G), 0.002);
  return f;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

Eigen::Isometry3d Matrix(const nlohmann::json& rows) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = rows[r][c].get<double>();
  }
  return T;
}

TEST(RefineE2E, UndoesHandEyeErrorPoseNoiseAndClockOffset) {
  const std::string dir = ScratchDir("e2e_refine_errors");
  const auto synth = RunCli(
      "synth --shape cylinder --claw three-finger --frames 30 --wall-m 0 "
      "--seed 3 --hand-eye-error 3,1 --pose-noise 0.5,0.2 "
      "--clock-offset-ms 15 -o " +
      dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const nlohmann::json errors = ReadJson(dir + "/scene.json")["rig_errors"];
  EXPECT_EQ(errors["clock_offset_us"].get<int64_t>(), 15000);
  EXPECT_NEAR(errors["E_C_angle_deg"].get<double>(), 1.0, 1e-6);

  const Fused refined = ReplayAndMeasure(dir, "--refine");
  const Fused logged = ReplayAndMeasure(dir, "--no-refine");
  ASSERT_GT(refined.points, 2000u);
  std::printf(
      "p95 to the truth: refined %.3f mm (%zu points, %d claw), logged poses %.3f mm "
      "(%zu points, %d claw)\n",
      1000 * refined.p95_m, refined.points, refined.claw_left, 1000 * logged.p95_m, logged.points,
      logged.claw_left);
  EXPECT_LE(refined.p95_m, 0.0010);
  EXPECT_LT(refined.claw_left, 0.001 * refined.points);
  // The same frames at their logged poses: several mm off. (The claw they
  // leave is mostly carved at extraction, where other views saw through
  // it: seen_free_carve.hpp; never less than the refined poses leave.)
  EXPECT_GT(logged.p95_m, 2.0 * refined.p95_m);
  EXPECT_GE(logged.claw_left, refined.claw_left);
  const nlohmann::json& r = refined.report["refine"];
  EXPECT_TRUE(r["enabled"].get<bool>());
  EXPECT_GE(r["frames_refined"].get<int>(), 27);
  EXPECT_EQ(refined.report["frames_used"].get<int>(), r["frames_refined"].get<int>());
  EXPECT_FALSE(logged.report["refine"]["enabled"].get<bool>());
}

// The table's hard case (below): the triangular prism in the parallel
// claw, with the errors, refined. A finger's hole in the prism's
// flat face opens into the top; fused at the refined poses, that face's
// rim comes out ragged, and the repair lost the hole (coverage 0.970
// against 0.995 error-free): the gap-direction linking chained 61 of its
// 407 boundary points, and the line the paper's rule chains took the
// rim's dip at the face's corner into the hole's mouth.
TEST(RefineE2E, APrismsFingerHoleIsFilledWithPoseErrors) {
  const std::string dir = ScratchDir("e2e_refine_prism_parallel");
  ASSERT_EQ(RunCli("synth --shape triangular-prism --claw parallel --seed 11 --hand-eye-error 3,1 "
                   "--pose-noise 0.5,0.2 --clock-offset-ms 15 -o " +
                   dir)
                .exit_code,
            0);
  const Fused f = ReplayAndMeasure(dir, "--refine", true);
  std::printf("coverage %.4f, p95 %.3f mm\n", f.coverage, 1000 * f.p95_m);
  EXPECT_GE(f.coverage, 0.99);
  int claw_holes = 0;
  for (const nlohmann::json& h : f.report["repair"]["holes"]) {
    if (h["kind"] == "claw") claw_holes += h["points_added"].get<int>() > 0;
  }
  EXPECT_EQ(claw_holes, 2) << f.report["repair"].dump();
  EXPECT_EQ(f.report["repair"]["claw_holes_left_open"].get<int>(), 0);
}

TEST(RefineE2E, HandEyeCorrectionMatchesTheInjectedError) {
  const std::string dir = ScratchDir("e2e_refine_hand_eye");
  const auto synth = RunCli(
      "synth --shape cuboid --claw parallel --frames 30 --wall-m 0 "
      "--seed 5 --hand-eye-error 3,1 --pose-noise 0.5,0.2 -o " +
      dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Eigen::Isometry3d E = Matrix(ReadJson(dir + "/scene.json")["rig_errors"]["E_C"]);
  const Fused refined = ReplayAndMeasure(dir, "--refine");
  const nlohmann::json& he = refined.report["refine"]["hand_eye_correction"];
  const Eigen::Isometry3d H = Matrix(he["H_C"]);
  const Eigen::Vector3d centre(he["claw_centre_C"][0].get<double>(), he["claw_centre_C"][1].get<double>(),
                               he["claw_centre_C"][2].get<double>());
  // H undoes E: H * E is the identity, up to the estimate's error.
  const Eigen::Isometry3d residual = H * E;
  const double at_claw_mm = 1000.0 * (residual * centre - centre).norm();
  const double deg = Eigen::AngleAxisd(residual.linear()).angle() * 180.0 / M_PI;
  std::printf(
      "hand-eye: injected %.3f deg; left after the correction %.3f mm at the claw, "
      "%.3f deg\n",
      Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI, at_claw_mm, deg);
  EXPECT_LT(at_claw_mm, 1.0);
  EXPECT_LT(deg, 0.3);
  EXPECT_LE(refined.p95_m, 0.0010);
}

// How far H leaves the claw from where E put it: H * E is the identity,
// up to the estimate's error [mm], [deg].
void HandEyeLeft(const nlohmann::json& refine, const Eigen::Isometry3d& E, double* at_claw_mm, double* deg) {
  const nlohmann::json& he = refine["hand_eye_correction"];
  const Eigen::Vector3d centre(he["claw_centre_C"][0].get<double>(), he["claw_centre_C"][1].get<double>(),
                               he["claw_centre_C"][2].get<double>());
  const Eigen::Isometry3d residual = Matrix(he["H_C"]) * E;
  *at_claw_mm = 1000.0 * (residual * centre - centre).norm();
  *deg = Eigen::AngleAxisd(residual.linear()).angle() * 180.0 / M_PI;
}

// A depth 1% long (synth --depth-scale) on top of a hand-eye error, 72
// frames (the scale is applied from the 48th): the
// claw's size tells the scale (the issue: within 0.2%), the depth is
// divided by it, and the hand-eye correction undoes the injected error
// (within 1 mm and 0.3 deg) instead of absorbing the scale's 5-6 mm along
// the ray. --no-depth-calibration reports the scale and leaves the depth,
// so the hand-eye correction takes the shift; --depth-scale gives it from
// the first frame. Exact depth: nothing applied.
TEST(RefineE2E, DepthScaleIsFoundAndNotTakenForTheHandEye) {
  for (const char* scale : {"1.01", "1"}) {
    const std::string dir = ScratchDir(std::string("e2e_refine_depth_scale_") + scale);
    ASSERT_EQ(RunCli("synth --shape cylinder --claw parallel --frames 72 --wall-m 0 --seed 6 "
                     "--hand-eye-error 3,1 --depth-scale " +
                     std::string(scale) + " -o " + dir)
                  .exit_code,
              0);
    const Eigen::Isometry3d E = Matrix(ReadJson(dir + "/scene.json")["rig_errors"]["E_C"]);
    const double truth = std::stod(scale);
    const Fused calibrated = ReplayAndMeasure(dir, "--refine");
    const nlohmann::json& refine = calibrated.report["refine"];
    const nlohmann::json& found = refine["depth_scale"];
    double mm = 0.0, deg = 0.0;
    HandEyeLeft(refine, E, &mm, &deg);
    std::printf(
        "depth scale %s: found %.4f +- %.4f, applied %.4f; hand-eye left %.2f mm, %.3f deg; "
        "fused p95 %.2f mm\n",
        scale, found["factor"].get<double>(), found["stderr"].get<double>(), found["applied"].get<double>(),
        mm, deg, 1000.0 * calibrated.p95_m);
    EXPECT_NEAR(found["factor"].get<double>(), truth, 0.002);
    EXPECT_LT(mm, 1.0);
    EXPECT_LT(deg, 0.3);
    if (truth == 1.0) {
      EXPECT_EQ(found["applied"].get<double>(), 1.0);
      EXPECT_EQ(found["changes"].get<int>(), 0);
      continue;
    }
    EXPECT_NEAR(found["applied"].get<double>(), truth, 0.002);
    const Fused reported = ReplayAndMeasure(dir, "--no-depth-calibration");
    const nlohmann::json& unapplied = reported.report["refine"]["depth_scale"];
    EXPECT_EQ(unapplied["applied"].get<double>(), 1.0);
    EXPECT_NEAR(unapplied["factor"].get<double>(), truth, 0.002);
    HandEyeLeft(reported.report["refine"], E, &mm, &deg);
    std::printf("  not applied: hand-eye left %.2f mm; fused p95 %.2f mm\n", mm, 1000.0 * reported.p95_m);
    EXPECT_GT(mm, 3.0);  // the scale's shift along the ray, taken for the hand-eye's
    EXPECT_LT(calibrated.p95_m, reported.p95_m);
    // Known beforehand (rig config camera.depth_scale): divided from the
    // first frame, nothing left to change, and no frame fused at the
    // wrong scale.
    const Fused known = ReplayAndMeasure(dir, "--depth-scale " + std::string(scale));
    const nlohmann::json& given = known.report["refine"]["depth_scale"];
    HandEyeLeft(known.report["refine"], E, &mm, &deg);
    std::printf("  known beforehand: found %.4f; hand-eye left %.2f mm; fused p95 %.2f mm\n",
                given["factor"].get<double>(), mm, 1000.0 * known.p95_m);
    EXPECT_EQ(given["applied"].get<double>(), truth);
    EXPECT_EQ(given["changes"].get<int>(), 0);
    EXPECT_NEAR(given["factor"].get<double>(), truth, 0.002);
    EXPECT_LT(mm, 1.0);
    EXPECT_LE(known.p95_m, calibrated.p95_m + 0.00005);
  }
}

// The clock offset (RefineConfig::clock_*): on a turn whose speed varies,
// the corrections' rotation follows the rate by -T, so the offset is found
// (the issue: within 3 ms) and the hand-eye part apart from it (within 1 mm
// and 0.3 deg); on a steady turn it cannot be, and is not applied.
TEST(RefineE2E, ClockOffsetIsFoundWhenTheSpeedVaries) {
  const std::string errors = "--hand-eye-error 3,1 --pose-noise 0.5,0.2 --clock-offset-ms 15 ";
  const std::string varying = ScratchDir("e2e_refine_clock_varying");
  ASSERT_EQ(RunCli("synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 --seed 8 "
                   "--speed-variation 0.6 " +
                   errors + "-o " + varying)
                .exit_code,
            0);
  const Fused found = ReplayAndMeasure(varying, "");
  const nlohmann::json& r = found.report["refine"];
  const nlohmann::json& clock = r["clock_offset"];
  ASSERT_FALSE(clock["offset_ms"].is_null()) << r.dump();
  std::printf("clock offset: injected 15 ms, found %.2f +- %.2f ms over %d frames (%s)\n",
              clock["offset_ms"].get<double>(), clock["stderr_ms"].get<double>(), clock["frames"].get<int>(),
              clock["applied"].get<bool>() ? "applied" : "not applied");
  EXPECT_TRUE(clock["applied"].get<bool>());
  EXPECT_NEAR(clock["offset_ms"].get<double>(), 15.0, 3.0);
  const Eigen::Isometry3d E = Matrix(ReadJson(varying + "/scene.json")["rig_errors"]["E_C"]);
  const nlohmann::json& he = r["hand_eye_correction"];
  const Eigen::Vector3d centre(he["claw_centre_C"][0].get<double>(), he["claw_centre_C"][1].get<double>(),
                               he["claw_centre_C"][2].get<double>());
  const Eigen::Isometry3d residual = Matrix(he["H_C"]) * E;
  const double at_claw_mm = 1000.0 * (residual * centre - centre).norm();
  const double deg = Eigen::AngleAxisd(residual.linear()).angle() * 180.0 / M_PI;
  std::printf("hand-eye beside it: left %.3f mm at the claw, %.3f deg\n", at_claw_mm, deg);
  EXPECT_LT(at_claw_mm, 1.0);
  EXPECT_LT(deg, 0.3);
  EXPECT_LE(found.p95_m, 0.0010);

  const std::string steady = ScratchDir("e2e_refine_clock_steady");
  ASSERT_EQ(RunCli("synth --shape cylinder --claw three-finger --frames 60 --wall-m 0 --seed 8 " + errors +
                   "-o " + steady)
                .exit_code,
            0);
  const Fused absorbed = ReplayAndMeasure(steady, "");
  const nlohmann::json& c2 = absorbed.report["refine"]["clock_offset"];
  EXPECT_FALSE(c2["applied"].get<bool>()) << c2.dump();
  // The constant correction absorbs it: the cloud is as good.
  EXPECT_LE(absorbed.p95_m, 0.0010);
}

// A large offset on a fast, varying turn (a sphere at -30 ms, up to 1.8x
// the mean speed): the part of the error that varies with the rate, up to
// ~3 deg, is beyond the jump bound before the offset is known. Such frames
// are not fused but feed the clock fit when their deviation is a turn
// about the motion's axis; without them the fit saw only the slow half,
// found -21 ms, never applied it and lost 45 of 90 frames.
TEST(RefineE2E, ALargeClockOffsetOnAFastTurnIsFound) {
  const std::string dir = ScratchDir("e2e_refine_clock_fast");
  ASSERT_EQ(RunCli("synth --shape sphere --claw parallel --wall-m 0 --seed 5 --speed-variation 0.8 "
                   "--hand-eye-error 3,1 --pose-noise 0.5,0.2 --clock-offset-ms -30 -o " +
                   dir)
                .exit_code,
            0);
  const Fused f = ReplayAndMeasure(dir, "");
  const nlohmann::json& r = f.report["refine"];
  const nlohmann::json& clock = r["clock_offset"];
  ASSERT_FALSE(clock["offset_ms"].is_null()) << r.dump();
  std::printf(
      "clock offset: injected -30 ms, found %.2f +- %.2f ms (%s), %d frames rejected, "
      "%d of them in the fit; p95 %.3f mm\n",
      clock["offset_ms"].get<double>(), clock["stderr_ms"].get<double>(),
      clock["applied"].get<bool>() ? "applied" : "not applied", r["frames_rejected"]["total"].get<int>(),
      clock["jump_frames_in_fit"].get<int>(), 1000.0 * f.p95_m);
  EXPECT_TRUE(clock["applied"].get<bool>());
  EXPECT_NEAR(clock["offset_ms"].get<double>(), -30.0, 3.0);
  EXPECT_GT(clock["jump_frames_in_fit"].get<int>(), 0);
  EXPECT_LE(r["frames_rejected"]["total"].get<int>(), 30);  // of 90
  EXPECT_LE(f.p95_m, 0.0010);
}

// The refinement table of docs/measurements/2026-12-03-imperfect-robots.md:
// every built-in shape of the paper, two zoo shapes and two mesh files
// (Debian's assimp-testmodels: a toy pig, y up, and a faceted ball with a
// hole; rows skipped with a note when the package is not installed), 90
// frames, error-free vs the errors with and without refinement,
// repair on. Minutes, so not in the suite:
//   build/bin/e2e_refine_test --gtest_also_run_disabled_tests --gtest_filter='*Table*'
TEST(RefineE2E, DISABLED_Table) {
  const std::string models = "/usr/share/assimp/models/";
  struct Case {
    std::string label, object, claw;
    std::string mesh_file;  ///< a mesh file the object needs, else empty
  };
  const std::string pig = models + "STL/Wuson.stl", ball = models + "STL/sphereWithHole.stl";
  const std::vector<Case> cases = {
      {"cuboid", "--shape cuboid", "three-finger", ""},
      {"triangular-prism", "--shape triangular-prism", "parallel", ""},
      {"cylinder", "--shape cylinder", "three-finger", ""},
      {"sphere", "--shape sphere", "parallel", ""},
      {"elliptic-cylinder", "--shape elliptic-cylinder", "three-finger", ""},
      {"ellipsoid", "--shape ellipsoid", "parallel", ""},
      {"bottle", "--shape bottle", "three-finger", ""},
      {"mug", "--shape mug", "parallel", ""},
      {"mesh Wuson.stl (x 0.05, y up)", "--mesh " + pig + " --mesh-scale 0.05 --mesh-up y", "three-finger",
       pig},
      {"mesh sphereWithHole.stl (x 0.02)", "--mesh " + ball + " --mesh-scale 0.02", "parallel", ball}};
  std::printf(
      "| shape, claw | p95 mm: no errors / refined / logged poses | claw pts: refined / "
      "logged | coverage: no errors / refined / logged | frames refined / rejected | "
      "hand-eye+clock correction found | refine ms/frame |\n|---|---|---|---|---|---|---|\n");
  // REFINE_TABLE_FROM=N starts at the N-th case (resuming a long run).
  const char* from = std::getenv("REFINE_TABLE_FROM");
  for (size_t index = 0; index < cases.size(); ++index) {
    const Case& c = cases[index];
    if (from && static_cast<int>(index) < std::atoi(from)) continue;
    if (!c.mesh_file.empty() && !std::filesystem::exists(c.mesh_file)) {
      std::printf("| %s, %s | not measured: %s is missing (apt-get install assimp-testmodels) |\n",
                  c.label.c_str(), c.claw.c_str(), c.mesh_file.c_str());
      continue;
    }
    const std::string name = std::to_string(index) + "_" + c.claw;
    const std::string clean = ScratchDir("refine_table_clean_" + name);
    const std::string bad = ScratchDir("refine_table_errors_" + name);
    const std::string common = "synth " + c.object + " --claw " + c.claw + " --seed 11 ";
    ASSERT_EQ(RunCli(common + "-o " + clean).exit_code, 0);
    ASSERT_EQ(
        RunCli(common + "--hand-eye-error 3,1 --pose-noise 0.5,0.2 --clock-offset-ms 15 -o " + bad).exit_code,
        0);
    const Fused f0 = ReplayAndMeasure(clean, "--refine", true);
    const Fused f1 = ReplayAndMeasure(bad, "--refine", true);
    const Fused f2 = ReplayAndMeasure(bad, "--no-refine", true);
    const nlohmann::json& r = f1.report["refine"];
    std::printf(
        "| %s, %s | %.2f / **%.2f** / %.2f | %d / %d | %.3f / **%.3f** / %.3f | %d / %d | "
        "%.1f mm at the claw, %.2f deg | %.2f |\n",
        c.label.c_str(), c.claw.c_str(), 1000 * f0.p95_m, 1000 * f1.p95_m, 1000 * f2.p95_m, f1.claw_left,
        f2.claw_left, f0.coverage, f1.coverage, f2.coverage, r["frames_refined"].get<int>(),
        r["frames_rejected"]["total"].get<int>(), r["hand_eye_correction"]["shift_at_claw_mm"].get<double>(),
        r["hand_eye_correction"]["rotation_deg"].get<double>(), r["ms_per_frame"].get<double>());
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace graspfill
