// SPDX-License-Identifier: BSD-3-Clause
// `graspfill eval` end to end on PLY files written here: exit codes, the
// messages naming the bad file, and the JSON it prints. RunEval is compiled
// into this test directly, so it runs without the whole CLI.
#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/io/TriangleMeshIO.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;

// kN x kN grid with 5 mm spacing in the plane z = `z` [m].
open3d::geometry::PointCloud Grid(double z) {
  constexpr int kN = 15;
  open3d::geometry::PointCloud c;
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) c.points_.emplace_back(i * 0.005, j * 0.005, z);
  }
  return c;
}

class CmdEvalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: ctest runs the tests of this file in parallel
    // processes, and one's fixture must not rewrite another's input.
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "cmd_eval" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
    gt_ = (dir_ / "gt.ply").string();
    pred_ = (dir_ / "pred.ply").string();
    ASSERT_TRUE(open3d::io::WritePointCloud(gt_, Grid(0.0)));
    ASSERT_TRUE(open3d::io::WritePointCloud(pred_, Grid(0.0015)));
  }

  // Runs RunEval, keeping what it printed.
  int Run(const Args& args) {
    ::testing::internal::CaptureStdout();
    ::testing::internal::CaptureStderr();
    const int rc = RunEval(args);
    out_ = ::testing::internal::GetCapturedStdout();
    err_ = ::testing::internal::GetCapturedStderr();
    return rc;
  }

  fs::path dir_;
  std::string gt_, pred_, out_, err_;
};

TEST_F(CmdEvalTest, JsonHasTheShiftedGridMetrics) {
  ASSERT_EQ(Run({pred_, gt_, "--json"}), 0) << err_;
  const nlohmann::json j = nlohmann::json::parse(out_);
  // 1.5 mm along the normal both ways: 2 * 1.5^2 mm^2.
  EXPECT_NEAR(j.at("chamfer_mm2").get<double>(), 4.5, 1e-5);
  EXPECT_EQ(j.at("fscore_1mm").get<double>(), 0.0);
  EXPECT_EQ(j.at("fscore_2mm").get<double>(), 1.0);
  EXPECT_EQ(j.at("coverage_2mm").get<double>(), 1.0);
  EXPECT_EQ(j.at("precision_2mm").get<double>(), 1.0);
  EXPECT_NEAR(j.at("p95_pred_to_gt_mm").get<double>(), 1.5, 1e-5);
  EXPECT_EQ(j.at("num_pred").get<size_t>(), 225u);
  EXPECT_EQ(j.at("num_gt").get<size_t>(), 225u);
  EXPECT_EQ(j.at("pred").get<std::string>(), pred_);
}

TEST_F(CmdEvalTest, HumanSummary) {
  ASSERT_EQ(Run({"--help"}), 0);
  ASSERT_EQ(Run({pred_, gt_}), 0) << err_;
  EXPECT_NE(out_.find("chamfer"), std::string::npos) << out_;
  EXPECT_NE(out_.find("mm^2"), std::string::npos) << out_;
  EXPECT_NE(out_.find("225 points"), std::string::npos) << out_;
}

TEST_F(CmdEvalTest, MeshGroundTruthIsReadAsVertices) {
  open3d::geometry::TriangleMesh mesh;
  const auto grid = Grid(0.0);
  mesh.vertices_ = grid.points_;
  mesh.triangles_.emplace_back(0, 1, 15);  // any face: makes it a mesh PLY
  const std::string mesh_path = (dir_ / "gt_mesh.ply").string();
  ASSERT_TRUE(open3d::io::WriteTriangleMesh(mesh_path, mesh));
  ASSERT_EQ(Run({pred_, mesh_path, "--json"}), 0) << err_;
  const nlohmann::json j = nlohmann::json::parse(out_);
  EXPECT_EQ(j.at("num_gt").get<size_t>(), grid.points_.size());
  EXPECT_NEAR(j.at("chamfer_mm2").get<double>(), 4.5, 1e-5);
}

TEST_F(CmdEvalTest, BadFilesNameTheFileAndExit1) {
  const std::string missing = (dir_ / "no_such.ply").string();
  EXPECT_EQ(Run({missing, gt_}), 1);
  EXPECT_NE(err_.find(missing), std::string::npos) << err_;

  const std::string garbage = (dir_ / "garbage.ply").string();
  std::ofstream(garbage) << "this is not a ply file\n";
  EXPECT_EQ(Run({pred_, garbage}), 1);
  EXPECT_NE(err_.find(garbage), std::string::npos) << err_;

  const std::string empty = (dir_ / "empty.ply").string();
  std::ofstream(empty) << "ply\nformat ascii 1.0\nelement vertex 0\n"
                          "property float x\nproperty float y\n"
                          "property float z\nend_header\n";
  EXPECT_EQ(Run({pred_, empty}), 1);
  EXPECT_NE(err_.find(empty), std::string::npos) << err_;

  const std::string nan = (dir_ / "nan.ply").string();
  std::ofstream(nan) << "ply\nformat ascii 1.0\nelement vertex 2\n"
                        "property float x\nproperty float y\n"
                        "property float z\nend_header\n0 0 0\nnan 0 0\n";
  EXPECT_EQ(Run({nan, gt_}), 1);
  EXPECT_NE(err_.find(nan), std::string::npos) << err_;
}

// The probe's 44-byte PLY (a header cut after `obj_info`, no newline):
// Open3D's reader segfaulted on it; PLY now goes through graspfill's own.
TEST_F(CmdEvalTest, ACutHeaderIsACleanErrorNotACrash) {
  const std::string cut = (dir_ / "cut.ply").string();
  {
    std::ofstream out(cut, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nobj_info";
  }
  ASSERT_EQ(fs::file_size(cut), 44u);
  EXPECT_EQ(Run({cut, gt_}), 1);
  EXPECT_NE(err_.find("predicted file: cannot read PLY '" + cut + "'"), std::string::npos) << err_;
  EXPECT_NE(err_.find("end_header"), std::string::npos) << err_;
  EXPECT_EQ(Run({pred_, cut}), 1);
  EXPECT_NE(err_.find("ground-truth file: cannot read PLY '" + cut + "'"), std::string::npos) << err_;
}

// Other formats still go through Open3D's readers.
TEST_F(CmdEvalTest, NonPlyFormatsAreStillRead) {
  const std::string xyz = (dir_ / "pred.xyz").string();
  ASSERT_TRUE(open3d::io::WritePointCloud(xyz, Grid(0.0015)));
  ASSERT_EQ(Run({xyz, gt_, "--json"}), 0) << err_;
  EXPECT_NEAR(nlohmann::json::parse(out_).at("chamfer_mm2").get<double>(), 4.5, 1e-5);
}

TEST_F(CmdEvalTest, WrongArgumentsExit2) {
  EXPECT_EQ(Run({}), 2);
  EXPECT_NE(err_.find("usage"), std::string::npos);
  EXPECT_EQ(Run({pred_}), 2);
  EXPECT_EQ(Run({pred_, gt_, gt_}), 2);
  EXPECT_EQ(Run({pred_, gt_, "--jsn"}), 2);
}

}  // namespace
}  // namespace graspfill::cli
