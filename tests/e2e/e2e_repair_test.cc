// SPDX-License-Identifier: BSD-3-Clause
// graspfill repair through the real CLI on the paper's protocol
// (synth --protocol paper): the contract (input kept, provenance, JSON
// report, determinism) and bad input (clear message, exit code, nothing
// overwritten).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "cli_runner.hpp"
#include "eval/metrics.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill {
namespace {

using testing::RunCli;
using testing::ScratchDir;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The JSON object in the CLI's output (Open3D may print warnings before it).
nlohmann::json JsonOf(const std::string& output) {
  return nlohmann::json::parse(output.substr(output.find('{')));
}

TEST(RepairCli, ProtocolCylinderIsRepairedToTheFloor) {
  const std::string dir = ScratchDir("e2e_repair_cylinder");
  ASSERT_EQ(RunCli("synth --protocol paper --shape cylinder --points 30000 -o " + dir).exit_code, 0);
  const auto run = RunCli("repair " + dir + "/holey.ply -o " + dir + "/repaired.ply --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = JsonOf(run.output);
  EXPECT_EQ(report["status"], "repaired");
  EXPECT_TRUE(report["symmetric"].get<bool>());
  int claw = 0, missing = 0, added = 0;
  for (const auto& h : report["holes"]) {
    claw += h["kind"] == "claw";
    missing += h["kind"] == "missing_surface";
    added += h["points_added"].get<int>();
  }
  EXPECT_EQ(claw, 3);
  EXPECT_EQ(missing, 1);
  EXPECT_TRUE(report["timings_ms"].contains("boundary_points"));

  const ObjectCloud holey = io::ReadCloudPly(dir + "/holey.ply");
  const ObjectCloud repaired = io::ReadCloudPly(dir + "/repaired.ply");
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  ASSERT_EQ(repaired.size(), holey.size() + static_cast<size_t>(added));
  EXPECT_EQ(report["points_out"].get<size_t>(), repaired.size());
  for (size_t i = 0; i < holey.size(); ++i) {
    ASSERT_EQ(repaired.points_G[i], holey.points_G[i]) << i;
    ASSERT_EQ(repaired.provenance[i], Provenance::kObserved) << i;
  }
  for (size_t i = holey.size(); i < repaired.size(); ++i) {
    ASSERT_NE(repaired.provenance[i], Provenance::kObserved) << i;
  }
  // The holes are closed: the chamfer drops by more than 10x (the bench
  // puts it at the sampling floor).
  const double before = eval::Compare(holey.points_G, gt.points_G).chamfer_mm2;
  const double after = eval::Compare(repaired.points_G, gt.points_G).chamfer_mm2;
  EXPECT_LT(after, 0.1 * before) << before << " -> " << after;

  // Deterministic: the same input gives the same bytes.
  ASSERT_EQ(RunCli("repair " + dir + "/holey.ply -o " + dir + "/again.ply").exit_code, 0);
  EXPECT_EQ(ReadFile(dir + "/repaired.ply"), ReadFile(dir + "/again.ply"));
}

// A fused cloud whose one boundary line (the open end's rim, in and out
// of both claw holes) the gap directions stopped, so that no hole was
// found: a large can in the parallel claw (bench repair --pipeline's row).
// The repair then links with the paper's rule alone.
TEST(RepairCli, ALargeCanInTheParallelClawGetsItsClawHolesFilled) {
  const std::string dir = ScratchDir("e2e_repair_large_can");
  ASSERT_EQ(RunCli("synth --shape cylinder --size 0.10x0.10x0.12 --claw parallel --grasp top-straight "
                   "--frames 90 --seed 11 -o " +
                   dir)
                .exit_code,
            0);
  const auto run =
      RunCli("replay " + dir + "/recording.lcmlog -o " + dir + "/repaired.ply --no-publish --json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = JsonOf(run.output)["repair"];
  int claw = 0, missing = 0;
  for (const auto& h : report["holes"]) {
    claw += h["kind"] == "claw";
    missing += h["kind"] == "missing_surface";
  }
  EXPECT_EQ(claw, 2) << report.dump();
  EXPECT_GE(missing, 1);
  // The target for a closed symmetric object: >= 97% of the true
  // surface within 2 mm of the model.
  const ObjectCloud repaired = io::ReadCloudPly(dir + "/repaired.ply");
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  const double coverage = eval::FractionWithin(mesh::NearestDistances(gt.points_G, repaired.points_G), 0.002);
  EXPECT_GE(coverage, 0.97);
}

TEST(RepairCli, BadInputGetsAClearMessageAndNothingIsOverwritten) {
  const std::string dir = ScratchDir("e2e_repair_bad");
  {
    std::ofstream(dir + "/nan.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                       "property float y\nproperty float z\nend_header\n"
                                       "0 0 0\nnan 1 1\n1 1 1\n";
    std::ofstream(dir + "/garbage.ply") << "not a ply at all";
  }
  auto r = RunCli("repair " + dir + "/nan.ply -o " + dir + "/out.ply");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("not a finite"), std::string::npos) << r.output;
  r = RunCli("repair " + dir + "/garbage.ply -o " + dir + "/out.ply");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("cannot read PLY"), std::string::npos) << r.output;
  r = RunCli("repair " + dir + "/missing.ply -o " + dir + "/out.ply");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.ply"));
  r = RunCli("repair " + dir + "/nan.ply -o " + dir + "/out.ply --mode nonsense");
  EXPECT_EQ(r.exit_code, 2);
  // An existing output is kept unless --force.
  std::ofstream(dir + "/keep.ply") << "precious";
  ASSERT_EQ(RunCli("synth --protocol paper --shape sphere --points 5000 -o " + dir + "/s").exit_code, 0);
  r = RunCli("repair " + dir + "/s/holey.ply -o " + dir + "/keep.ply");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(ReadFile(dir + "/keep.ply"), "precious");
  // A tiny cloud is a documented no-op.
  std::ofstream(dir + "/tiny.ply") << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                      "property float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n";
  r = RunCli("repair " + dir + "/tiny.ply -o " + dir + "/tiny_out.ply --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(JsonOf(r.output)["status"].get<std::string>().find("too few points"), std::string::npos);
  EXPECT_EQ(io::ReadCloudPly(dir + "/tiny_out.ply").size(), 2u);
}

// A cloud in millimetres is beyond the repair's extent: it used to come
// back unchanged with exit 0. It is an error naming the fix, nothing is
// written, and --scale 0.001 repairs it as the cloud in meters.
TEST(RepairCli, ACloudInMillimetresIsAnErrorWithTheScaleHint) {
  const std::string dir = ScratchDir("e2e_repair_units");
  ASSERT_EQ(RunCli("synth --protocol paper --shape cylinder --points 20000 -o " + dir + "/s").exit_code, 0);
  ObjectCloud mm = io::ReadCloudPly(dir + "/s/holey.ply");
  for (Eigen::Vector3f& p : mm.points_G) p *= 1000.0f;
  io::WriteCloudPly(dir + "/holey_mm.ply", mm);

  auto r = RunCli("repair " + dir + "/holey_mm.ply -o " + dir + "/out.ply");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("--scale 0.001"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("outside the repair's limits"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.ply"));

  r = RunCli("repair " + dir + "/holey_mm.ply -o " + dir + "/scaled.ply --scale 0.001");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ObjectCloud scaled = io::ReadCloudPly(dir + "/scaled.ply");
  ASSERT_EQ(RunCli("repair " + dir + "/s/holey.ply -o " + dir + "/meters.ply").exit_code, 0);
  const ObjectCloud meters = io::ReadCloudPly(dir + "/meters.ply");
  ASSERT_GT(meters.size(), mm.size());  // repaired, not passed through
  // The same repair up to float rounding of the scaled input: the added
  // points agree within 1% in number and the inputs within a micrometre.
  EXPECT_NEAR(static_cast<double>(scaled.size()), static_cast<double>(meters.size()), 0.01 * meters.size());
  for (size_t i = 0; i < mm.size(); i += 97) {
    EXPECT_LT((scaled.points_G[i] - meters.points_G[i]).norm(), 1e-6f) << i;
  }
  EXPECT_EQ(RunCli("repair " + dir + "/holey_mm.ply -o " + dir + "/x.ply --scale 0").exit_code, 2);
}

// -o x.pcd used to write PLY bytes under a .pcd name (Open3D then read 0
// points). The name picks the format: the PCD holds the same points as the
// PLY, read back by Open3D; an unknown extension is a usage error before
// any work, and a PCD given as input is refused with what to do.
TEST(RepairCli, ThePcdOutputIsPcdAndOtherNamesAreRefused) {
  const std::string dir = ScratchDir("e2e_repair_pcd");
  ASSERT_EQ(RunCli("synth --protocol paper --shape cylinder --points 20000 -o " + dir + "/s").exit_code, 0);
  ASSERT_EQ(RunCli("repair " + dir + "/s/holey.ply -o " + dir + "/out.ply").exit_code, 0);
  const auto r = RunCli("repair " + dir + "/s/holey.ply -o " + dir + "/out.pcd");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ObjectCloud ply = io::ReadCloudPly(dir + "/out.ply");
  open3d::geometry::PointCloud pcd;
  ASSERT_TRUE(open3d::io::ReadPointCloud(dir + "/out.pcd", pcd));
  ASSERT_EQ(pcd.points_.size(), ply.size());
  ASSERT_GT(ply.size(), 20000u);  // repaired
  for (size_t i = 0; i < ply.size(); i += 101) {
    EXPECT_EQ(pcd.points_[i], ply.points_G[i].cast<double>()) << i;
  }

  auto bad = RunCli("repair " + dir + "/s/holey.ply -o " + dir + "/out.xyz");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("a cloud is written as .ply or .pcd"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.xyz"));
  // replay too: -o model.pcd is PCD, the same points as -o model.ply.
  const std::string log = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";
  ASSERT_EQ(RunCli("replay " + log + " -o " + dir + "/model.ply --no-publish").exit_code, 0);
  const auto replay = RunCli("replay " + log + " -o " + dir + "/model.pcd --no-publish");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  open3d::geometry::PointCloud model;
  ASSERT_TRUE(open3d::io::ReadPointCloud(dir + "/model.pcd", model));
  EXPECT_EQ(model.points_.size(), io::ReadCloudPly(dir + "/model.ply").size());
  bad = RunCli("replay " + log + " -o " + dir + "/model.txt --no-publish");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("a cloud is written as .ply or .pcd"), std::string::npos) << bad.output;
  bad = RunCli("repair " + dir + "/out.pcd -o " + dir + "/again.ply");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("give the cloud as .ply"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/again.ply"));
}

}  // namespace
}  // namespace graspfill
