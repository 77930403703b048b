// SPDX-License-Identifier: BSD-3-Clause
// bench repair --objects end to end: a tiny set made here from two real
// scans (../shared/assets/objects: a PLY from the tune split and an OBJ
// from the check split), one claw, one grasp, one seed. Its rows are
// checked against the clouds it dumps (coverage, the fused cloud's p99,
// the added points' errors measured here from the files), the targets'
// verdict against the issue's thresholds, the summary against the rows, a
// second run for the same bytes. Then the manifest's and the options'
// errors, and a row whose object the claw cannot hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "eval/metrics.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill {
namespace {

namespace fs = std::filesystem;
using testing::ObservedPoints;
using testing::RunCli;
using testing::ScratchDir;

const fs::path kAssets = fs::path(GRASPFILL_SOURCE_DIR) / ".." / "shared" / "assets" / "objects";

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The JSON document a command printed (stdout and stderr are merged: it
// starts at the first '{' that starts a line).
nlohmann::json JsonOf(const std::string& output) {
  const size_t start = output.rfind('{', 0) == 0 ? 0 : output.find("\n{") + 1;
  return nlohmann::json::parse(output.substr(start));
}

// A closed axis-aligned box mesh, W x D x H meters, as OBJ.
// A w x d x h box standing on z = 0, as OBJ; with `chamfer` > 0 its bottom
// edges are cut at 45 degrees that deep (a toy block's bevel).
std::string BoxObj(double w, double d, double h, double chamfer = 0.0) {
  std::ostringstream obj;
  // Rings of four corners, counter-clockwise seen from +z: the bottom
  // (inset by the chamfer), the chamfer's top (when cut) and the top.
  std::vector<std::pair<double, double>> rings = {{chamfer, 0.0}};
  if (chamfer > 0.0) rings.emplace_back(0.0, chamfer);
  rings.emplace_back(0.0, h);
  for (const auto& [inset, z] : rings) {
    const double x = w / 2 - inset, y = d / 2 - inset;
    obj << "v " << -x << " " << -y << " " << z << "\nv " << x << " " << -y << " " << z << "\nv " << x << " "
        << y << " " << z << "\nv " << -x << " " << y << " " << z << "\n";
  }
  // Outward faces, 1-based: the bottom, the bands between rings, the top.
  obj << "f 1 3 2\nf 1 4 3\n";
  for (int r = 0; r + 1 < static_cast<int>(rings.size()); ++r) {
    for (int i = 0; i < 4; ++i) {
      const int a = 4 * r + i + 1, b = 4 * r + (i + 1) % 4 + 1;
      obj << "f " << a << " " << b << " " << b + 4 << "\nf " << a << " " << b + 4 << " " << a + 4 << "\n";
    }
  }
  const int t = 4 * static_cast<int>(rings.size() - 1);
  obj << "f " << t + 1 << " " << t + 2 << " " << t + 3 << "\nf " << t + 1 << " " << t + 3 << " " << t + 4
      << "\n";
  return obj.str();
}

double Get(const nlohmann::json& row, const char* key) { return row.at(key).get<double>(); }

// The one row of `bench repair --objects DIR ARGS --seeds 1 --repeat 1
// --json` (a missing "rows" throws, which fails the test).
nlohmann::json OnlyRow(const std::string& dir, const std::string& args) {
  const auto run = RunCli("bench repair --objects " + dir + " " + args + " --seeds 1 --repeat 1 --json");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json rows = JsonOf(run.output).at("rows");
  EXPECT_EQ(rows.size(), 1u);
  return rows.empty() ? nlohmann::json::object() : rows[0];
}

TEST(BenchObjectsE2E, TwoScansOneClawGraspSeedRowsMatchTheirDumpedClouds) {
  if (!fs::exists(kAssets / "objects.json")) {
    GTEST_SKIP() << "the real scans are not here (" << kAssets.string()
                 << "/objects.json: ../shared/assets is absent); nothing to run on";
  }
  const std::string dir = ScratchDir("bench_objects");
  const std::string set = dir + "/set";
  fs::create_directories(set);
  fs::copy_file(kAssets / "058_golf_ball.ply", set + "/058_golf_ball.ply");
  fs::copy_file(kAssets / "005_tomato_soup_can.obj", set + "/005_tomato_soup_can.obj");
  WriteText(set + "/objects.json", R"({"_about": "two scans, one of each format",
    "objects": {
      "058_golf_ball": {"file": "058_golf_ball.ply", "kind": "closed_symmetric", "split": "tune"},
      "005_tomato_soup_can": {"file": "005_tomato_soup_can.obj", "kind": "closed_symmetric", "split": "check"}}})");
  fs::create_directories(dir + "/dump");
  const std::string args = "bench repair --objects " + set +
                           " --claw three-finger --grasp top-straight --seeds 1 --repeat 1 --json --dump ";
  const auto run = RunCli(args + dir + "/dump");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json out = JsonOf(run.output);
  const nlohmann::json& rows = out.at("rows");
  // objects x claws x grasps x seeds, in the manifest's order.
  ASSERT_EQ(rows.size(), 2u * 1u * 1u * 1u) << run.output;
  EXPECT_EQ(rows[0]["object"], "058_golf_ball");
  EXPECT_EQ(rows[1]["object"], "005_tomato_soup_can");
  EXPECT_EQ(rows[0]["split"], "tune");
  EXPECT_EQ(rows[1]["split"], "check");

  const char* names[] = {"058_golf_ball", "005_tomato_soup_can"};
  const double extent_m[] = {0.0427, 0.1019};  // the scans' largest sizes (assets README)
  int met = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const nlohmann::json& row = rows[i];
    SCOPED_TRACE(row.dump());
    EXPECT_EQ(row["kind"], "closed_symmetric");
    EXPECT_EQ(row["claw"], "three-finger");
    EXPECT_EQ(row["grasp"], "top-straight");
    EXPECT_EQ(row["seed"], 1);
    ASSERT_TRUE(row["ran"].get<bool>());  // both fit the three-finger claw
    EXPECT_FALSE(row["workspace_grown"].get<bool>());

    const std::string stem = dir + "/dump/" + names[i] + "_three-finger_top-straight_s1_";
    const ObjectCloud truth = io::ReadCloudPly(stem + "truth.ply");
    const ObjectCloud fused = io::ReadCloudPly(stem + "fused.ply");
    const ObjectCloud repaired = io::ReadCloudPly(stem + "repaired.ply");
    // The mesh read in meters and whole: the truth spans the scan's size.
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& p : truth.points_G) box.extend(p);
    EXPECT_NEAR(box.sizes().maxCoeff(), extent_m[i], 0.002);
    ASSERT_GT(fused.size(), 1000u);
    EXPECT_EQ(row["fused_points"].get<size_t>(), fused.size());
    EXPECT_EQ(row["points"].get<size_t>(), repaired.size());
    EXPECT_EQ(row["added"].get<size_t>(), repaired.size() - fused.size());
    // The repair keeps the fused points first, as they were.
    ASSERT_GE(repaired.size(), fused.size());
    EXPECT_TRUE(std::equal(fused.points_G.begin(), fused.points_G.end(), repaired.points_G.begin()));
    EXPECT_EQ(ObservedPoints(repaired).size(), fused.size());

    // The row's numbers, measured here from the files.
    const std::vector<double> fused_to_truth = mesh::NearestDistances(fused.points_G, truth.points_G);
    const double fused_p99_mm = 1000.0 * Percentile(fused_to_truth, 99.0);
    EXPECT_NEAR(Get(row, "fused_p95_mm"), 1000.0 * Percentile(fused_to_truth, 95.0), 1e-6);
    EXPECT_NEAR(Get(row, "fused_off_object_share"), 1.0 - eval::FractionWithin(fused_to_truth, 0.003), 1e-9);
    const double fused_coverage =
        eval::FractionWithin(mesh::NearestDistances(truth.points_G, fused.points_G), 0.002);
    const double coverage =
        eval::FractionWithin(mesh::NearestDistances(truth.points_G, repaired.points_G), 0.002);
    EXPECT_NEAR(Get(row, "fused_p99_mm"), fused_p99_mm, 1e-6);
    EXPECT_NEAR(Get(row, "fused_coverage"), fused_coverage, 1e-9);
    EXPECT_NEAR(Get(row, "coverage_2mm"), coverage, 1e-9);
    EXPECT_GT(fused_p99_mm, 0.0);
    EXPECT_LT(fused_p99_mm, 20.0);  // a fused cloud on the object, not beside it
    EXPECT_GT(coverage, 0.5);
    EXPECT_LE(coverage, 1.0);
    EXPECT_GE(coverage, fused_coverage);
    double added_p95_mm = 0.0, wrong = 0.0;
    if (repaired.size() > fused.size()) {
      const std::vector<Eigen::Vector3f> added(repaired.points_G.begin() + fused.size(),
                                               repaired.points_G.end());
      const std::vector<double> d = mesh::NearestDistances(added, truth.points_G);
      added_p95_mm = 1000.0 * Percentile(d, 95.0);
      wrong = 1.0 - eval::FractionWithin(d, 0.003);
    }
    EXPECT_NEAR(Get(row, "added_p95_mm"), added_p95_mm, 1e-6);
    EXPECT_NEAR(Get(row, "wrong_share"), wrong, 1e-9);
    EXPECT_GE(Get(row, "seen_free_points"), 0.0);
    EXPECT_GT(Get(row, "repair_ms"), 0.0);
    // The verdict: the issue's closed_symmetric targets.
    const bool meets =
        coverage >= 0.97 && added_p95_mm <= 2.0 && wrong <= 0.02 && row["seen_free_points"].get<int>() == 0;
    EXPECT_EQ(row["meets"].get<bool>(), meets);
    EXPECT_EQ(row["failed"].empty(), meets);
    met += meets;
  }
  // The tune split's golf ball closes: its top completed, the targets met.
  EXPECT_TRUE(rows[0]["meets"].get<bool>()) << rows[0].dump();
  EXPECT_NE(rows[0]["top_completion"], "open");
  const nlohmann::json& summary = out.at("summary");
  EXPECT_EQ(summary["all"]["rows"], 2);
  EXPECT_EQ(summary["all"]["met"], met);
  EXPECT_EQ(summary["by_split"]["tune"]["rows"], 1);
  EXPECT_EQ(summary["by_split"]["check"]["rows"], 1);
  EXPECT_EQ(summary["by_split"]["tune"]["met"], rows[0]["meets"].get<bool>() ? 1 : 0);
  EXPECT_EQ(summary["by_kind"]["closed_symmetric"]["rows"], 2);
  EXPECT_NEAR(summary["by_object"]["058_golf_ball"]["fused_p99_mm_max"].get<double>(),
              Get(rows[0], "fused_p99_mm"), 1e-12);

  // Deterministic for a seed: the tune split alone gives the same clouds.
  fs::create_directories(dir + "/again");
  const auto again =
      RunCli("bench repair --objects " + set +
             " --split tune --claw three-finger --grasp top-straight --seeds 1 --repeat 1 --json"
             " --dump " +
             dir + "/again");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const nlohmann::json rows2 = JsonOf(again.output).at("rows");
  ASSERT_EQ(rows2.size(), 1u);
  for (const char* what : {"truth", "fused", "repaired"}) {
    const std::string name = std::string("058_golf_ball_three-finger_top-straight_s1_") + what + ".ply";
    EXPECT_EQ(ReadText(dir + "/dump/" + name), ReadText(dir + "/again/" + name)) << name;
  }
  for (const char* key : {"fused_p99_mm", "coverage_2mm", "added_p95_mm", "wrong_share"}) {
    EXPECT_EQ(rows2[0][key], rows[0][key]) << key;
  }
  // The dump is never written over.
  const auto taken = RunCli(args + dir + "/dump");
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_NE(taken.output.find("exists (not overwritten)"), std::string::npos) << taken.output;
}

// A cup of the tune split held by its rim, its inside never seen: the
// search leaves its mouth open instead of capping it, so nothing wrong is
// added and its kind's targets are met; the planner's safe bound still
// holds the whole cup, the inside nobody saw included.
TEST(BenchObjectsE2E, AnOpenCupsUnseenMouthIsLeftOpen) {
  if (!fs::exists(kAssets / "objects.json")) {
    GTEST_SKIP() << "the real scans are not here (" << kAssets.string()
                 << "/objects.json: ../shared/assets is absent); nothing to run on";
  }
  const std::string dir = ScratchDir("bench_objects_cup");
  fs::create_directories(dir);
  fs::copy_file(kAssets / "065-c_cups.ply", dir + "/065-c_cups.ply");
  WriteText(dir + "/objects.json", R"({"objects": {
      "065-c_cups": {"file": "065-c_cups.ply", "kind": "open", "split": "tune"}}})");
  const nlohmann::json row = OnlyRow(dir, "--claw parallel --grasp top-straight");
  SCOPED_TRACE(row.dump());
  ASSERT_TRUE(row["ran"].get<bool>());
  EXPECT_EQ(row["top_completion"], "open");
  EXPECT_LE(Get(row, "wrong_share"), 0.02);
  EXPECT_GE(Get(row, "coverage_2mm"), Get(row, "fused_coverage"));
  EXPECT_EQ(row["seen_free_points"].get<int>(), 0);
  EXPECT_EQ(Get(row, "truth_outside_bound"), 0.0);
  EXPECT_TRUE(row["meets"].get<bool>());
}

// A block whose bottom edges are bevelled 3 mm, held by its top: the
// mirror image of its bevelled bottom would bevel its lid too, and the
// walls are those of a prism all the way down, so the search closes it by
// the extrusion of its top's outline, at the rays' height. No view saw
// that lid, and a tray's mouth would end the walls alike: it comes with a
// coin flip's confidence, and the points the repair stands behind are the
// rest.
TEST(BenchObjectsE2E, AChamferedBlocksLidIsTheExtrusionOfItsWalls) {
  const std::string dir = ScratchDir("bench_objects_block");
  WriteText(dir + "/block.obj", BoxObj(0.05, 0.035, 0.08, 0.003));
  WriteText(dir + "/objects.json",
            R"({"objects": {"block": {"file": "block.obj", "kind": "closed_symmetric", "split": "tune"}}})");
  const nlohmann::json row = OnlyRow(dir, "--claw parallel --grasp top-oblique");
  SCOPED_TRACE(row.dump());
  EXPECT_EQ(row["top_completion"], "extrusion");
  EXPECT_EQ(Get(row, "top_confidence"), 0.5);
  EXPECT_TRUE(row["meets"].get<bool>());
  EXPECT_TRUE(row["meets_on_trusted"].get<bool>());
  EXPECT_LT(Get(row, "trusted_added"), 0.5 * Get(row, "added"));
  EXPECT_LE(Get(row, "trusted_wrong_share"), 0.02);
}

// A can (66 x 101 mm) or a cup with the same outside, a 2 mm wall and no
// lid (its inside 5 mm over its bottom), as OBJ: the pair of
// scripts/can_and_cup.py, 96 facets around.
std::string CanOrCupObj(bool cup) {
  constexpr int kSegments = 96, kRings = 20;  // around the axis, along a wall
  constexpr double kRadius = 0.033, kHeight = 0.101, kWall = 0.002, kInnerBottom = 0.005;
  std::ostringstream obj;
  obj.precision(9);  // as the script's float32 vertices
  int vertices = 0;
  // A ring of kSegments vertices; returns its first (1-based).
  const auto ring = [&](double r, double z) {
    for (int k = 0; k < kSegments; ++k) {
      const double t = 2.0 * M_PI * k / kSegments;
      obj << "v " << r * std::cos(t) << " " << r * std::sin(t) << " " << z << "\n";
    }
    vertices += kSegments;
    return vertices - kSegments + 1;
  };
  // Rings from (r0, z0) to (r1, z1), faces out: up the outside, in across
  // the rim, down the inside.
  const auto band = [&](double r0, double z0, double r1, double z1, int steps) {
    int a = ring(r0, z0);
    for (int s = 1; s <= steps; ++s) {
      const int b = ring(r0 + (r1 - r0) * s / steps, z0 + (z1 - z0) * s / steps);
      for (int k = 0; k < kSegments; ++k) {
        const int k1 = (k + 1) % kSegments;
        obj << "f " << a + k << " " << a + k1 << " " << b + k1 << "\nf " << a + k << " " << b + k1 << " "
            << b + k << "\n";
      }
      a = b;
    }
  };
  const auto disc = [&](double r, double z, bool up) {
    obj << "v 0 0 " << z << "\n";
    const int centre = ++vertices;
    const int first = ring(r, z);
    for (int k = 0; k < kSegments; ++k) {
      const int a = first + k, b = first + (k + 1) % kSegments;
      obj << "f " << centre << " " << (up ? a : b) << " " << (up ? b : a) << "\n";
    }
  };
  disc(kRadius, 0.0, false);
  band(kRadius, 0.0, kRadius, kHeight, kRings);
  if (!cup) {
    disc(kRadius, kHeight, true);
  } else {
    band(kRadius, kHeight, kRadius - kWall, kHeight, 1);  // the rim
    band(kRadius - kWall, kHeight, kRadius - kWall, kInnerBottom, kRings);
    disc(kRadius - kWall, kInnerBottom, true);
  }
  return obj.str();
}

// The can and the cup, held by their tops (parallel claw, top-straight,
// seed 1): the repair is given byte-identical clouds
// (docs/measurements/2026-12-07-can-or-cup.md), so one of the issue's two
// targets must fail. Their lid is added with a coin flip's confidence:
// the can meets the stated targets, the cup misses them, and both meet
// the case proposed beside them (the wrong share over the points with
// confidence > 0.5).
TEST(BenchObjectsE2E, ACanAndACupWithTheSameOutsideMeetTheProposedCase) {
  const std::string dir = ScratchDir("bench_objects_can_or_cup");
  WriteText(dir + "/can.obj", CanOrCupObj(false));
  WriteText(dir + "/cup.obj", CanOrCupObj(true));
  WriteText(dir + "/objects.json", R"({"objects": {
      "can": {"file": "can.obj", "kind": "closed_symmetric", "split": "tune"},
      "cup": {"file": "cup.obj", "kind": "open", "split": "tune"}}})");
  const auto run = RunCli("bench repair --objects " + dir +
                          " --claw parallel --grasp top-straight --seeds 1 --repeat 1 --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json out = JsonOf(run.output);
  const nlohmann::json& rows = out.at("rows");
  ASSERT_EQ(rows.size(), 2u);
  const nlohmann::json& can = rows[0]["object"] == "can" ? rows[0] : rows[1];
  const nlohmann::json& cup = rows[0]["object"] == "can" ? rows[1] : rows[0];
  SCOPED_TRACE(rows.dump());
  EXPECT_EQ(can["fused_points"], cup["fused_points"]);
  EXPECT_EQ(can["added"], cup["added"]);
  for (const nlohmann::json* row : {&can, &cup}) {
    EXPECT_EQ((*row)["top_completion"], "mirror");
    EXPECT_EQ(Get(*row, "top_confidence"), 0.5);
    EXPECT_TRUE((*row)["meets_on_trusted"].get<bool>());
    EXPECT_LE(Get(*row, "trusted_wrong_share"), 0.02);
  }
  EXPECT_TRUE(can["meets"].get<bool>());
  EXPECT_FALSE(cup["meets"].get<bool>());
  EXPECT_GT(Get(cup, "wrong_share"), 0.1);  // the lid over its mouth
  const nlohmann::json& proposed = out.at("summary").at("on_trusted_by_split_kind").at("tune");
  EXPECT_EQ(proposed.at("open").at("met"), 1);
  EXPECT_EQ(proposed.at("closed_symmetric").at("met"), 1);
}

// An object the claw cannot hold stays in the table: not met, and why.
TEST(BenchObjectsE2E, AnObjectTooBigForTheClawIsARowNotMet) {
  const std::string dir = ScratchDir("bench_objects_big");
  WriteText(dir + "/crate.obj", BoxObj(0.24, 0.24, 0.10));  // 24 cm square: past the 8 cm opening
  WriteText(dir + "/objects.json",
            R"({"objects": {"crate": {"file": "crate.obj", "kind": "closed_symmetric", "split": "check"}}})");
  const auto r = RunCli("bench repair --objects " + dir +
                        " --claw three-finger,parallel --grasp top-straight --seeds 4");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("crate"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no: too big for the claw"), std::string::npos) << r.output;
  const auto j = RunCli("bench repair --objects " + dir +
                        " --claw three-finger,parallel --grasp top-straight "
                        "--seeds 4 --json");
  ASSERT_EQ(j.exit_code, 0) << j.output;
  const nlohmann::json out = JsonOf(j.output);
  ASSERT_EQ(out["rows"].size(), 2u);
  for (const nlohmann::json& row : out["rows"]) {
    EXPECT_FALSE(row["ran"].get<bool>());
    EXPECT_FALSE(row["meets"].get<bool>());
    EXPECT_FALSE(row["meets_on_trusted"].get<bool>());  // nor the proposed case: nothing ran
    EXPECT_TRUE(row["coverage_2mm"].is_null());
    EXPECT_GT(Get(row, "opening_mm"), 80.0);
    EXPECT_NE(row["reason"].get<std::string>().find("too big for the claw"), std::string::npos);
    EXPECT_EQ(row["failed"][0]["field"], "grasped");
  }
  EXPECT_EQ(out["summary"]["all"]["rows"], 2);
  EXPECT_EQ(out["summary"]["all"]["met"], 0);
}

// A set that cannot be used is refused before any work, exit 2, with a
// message that names the file and the problem.
TEST(BenchObjectsE2E, ManifestErrorsAreNamedAndExitTwo) {
  const std::string root = ScratchDir("bench_objects_bad");
  struct Case {
    std::string name;
    std::string manifest;  // "" : no objects.json at all
    std::string message;
  };
  const std::string box = R"("file": "box.obj")";
  const std::vector<Case> cases = {
      {"missing", "", "/objects.json: not found"},
      {"not_json", "{\"objects\": {", "/objects.json: not valid JSON"},
      {"array", "[1, 2]", "/objects.json: expected a JSON object"},
      {"no_objects", R"({"_about": "x"})", "/objects.json: no \"objects\""},
      {"empty", R"({"objects": {}})", "\"objects\" must be a non-empty object"},
      {"top_key", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "tune"}}, "extra": 1})",
       "unknown key 'extra'"},
      {"kind", R"({"objects": {"a": {)" + box + R"(, "kind": "round", "split": "tune"}}})",
       "object 'a': unknown kind 'round' (closed_symmetric, closed_asymmetric or open)"},
      {"split", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "train"}}})",
       "object 'a': unknown split 'train' (tune or check)"},
      {"no_kind", R"({"objects": {"a": {)" + box + R"(, "split": "tune"}}})", "object 'a': no \"kind\""},
      {"file_type", R"({"objects": {"a": {"file": 3, "kind": "open", "split": "tune"}}})",
       "object 'a': \"file\" must be a string"},
      {"entry_key", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "tune", "knd": 1}}})",
       "object 'a': unknown key 'knd'"},
      {"no_mesh", R"({"objects": {"a": {"file": "gone.ply", "kind": "open", "split": "tune"}}})",
       "object 'a': mesh '"},
      {"scale", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "tune", "mesh_scale": -1}}})",
       "object 'a': \"mesh_scale\" must be a number"},
      {"up", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "tune", "mesh_up": "x"}}})",
       "object 'a': \"mesh_up\" must be \"z\" or \"y\""},
      {"bad_mesh", R"({"objects": {"a": {"file": "junk.ply", "kind": "open", "split": "tune"}}})",
       "object 'a' in "},
      {"huge", R"({"objects": {"a": {)" + box + R"(, "kind": "open", "split": "tune", "mesh_scale": 1000}}})",
       "graspfill expects meters"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string dir = root + "/" + c.name;
    fs::create_directories(dir);
    WriteText(dir + "/box.obj", BoxObj(0.05, 0.05, 0.08));
    WriteText(dir + "/junk.ply", "ply\nformat nonsense\n");
    if (!c.manifest.empty()) WriteText(dir + "/objects.json", c.manifest);
    const auto r = RunCli("bench repair --objects " + dir);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(dir + "/objects.json"), std::string::npos) << r.output;
  }
  // A folder that is not there.
  const auto gone = RunCli("bench repair --objects " + root + "/nowhere");
  EXPECT_EQ(gone.exit_code, 2);
  EXPECT_NE(gone.output.find("'" + root + "/nowhere' is not a directory"), std::string::npos) << gone.output;

  // Options on a good set: an object it does not list, a split with none.
  const std::string good = root + "/good";
  fs::create_directories(good);
  WriteText(good + "/box.obj", BoxObj(0.05, 0.05, 0.08));
  WriteText(good + "/objects.json",
            R"({"objects": {"box": {"file": "box.obj", "kind": "closed_symmetric", "split": "tune"}}})");
  const std::vector<std::pair<std::string, std::string>> usage = {
      {"--object cup", "--object 'cup': not in " + good + "/objects.json"},
      {"--split check", "no object of " + good + "/objects.json is in split 'check'"},
      {"--split train", "--split 'train': expected tune or check"},
      {"--claw robotiq", "--claw 'robotiq': expected three-finger or parallel"},
      {"--grasp side", "--grasp 'side': expected top-straight"},
      {"--seeds 1,,2", "--seeds '1,,2': an empty item"},
      {"--seeds 1,1", "--seeds '1,1': '1' twice"},
      {"--seeds x", "--seeds 'x': not an integer"},
      {"--frames 5", "--frames '5': out of range, expected 10..3000"},
      {"--dump", "--dump needs a value"},
      {"--dark-patches 0.9", "--dark-patches '0.9': out of range, expected 0..0.5"},
      {"--mixed-pixels", "--mixed-pixels needs a value"},
      {"--bogus", "bad option '--bogus'"},
  };
  for (const auto& [option, message] : usage) {
    SCOPED_TRACE(option);
    const auto r = RunCli("bench repair --objects " + good + " " + option);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
  }
  const auto no_dir = RunCli("bench repair --objects");
  EXPECT_EQ(no_dir.exit_code, 2);
  EXPECT_NE(no_dir.output.find("--objects needs a value"), std::string::npos) << no_dir.output;
  const auto both = RunCli("bench repair --objects " + good + " --pipeline");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.output.find("--objects and --pipeline"), std::string::npos) << both.output;
  const auto dump = RunCli("bench repair --objects " + good + " --dump " + root + "/nodir");
  EXPECT_EQ(dump.exit_code, 1);
  EXPECT_NE(dump.output.find("is not a directory"), std::string::npos) << dump.output;
}

}  // namespace
}  // namespace graspfill
