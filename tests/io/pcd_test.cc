// SPDX-License-Identifier: BSD-3-Clause
// PCD clouds (io/pcd.hpp) read back by Open3D, an independent reader: the
// point count, coordinates, normals, colours and the custom provenance and
// confidence fields; VIEWPOINT as the camera's pose in G; determinism; and
// the extension dispatch of io/cloud_file.hpp.
#include "graspfill/io/pcd.hpp"

#include <gtest/gtest.h>

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/t/geometry/PointCloud.h>
#include <open3d/t/io/PointCloudIO.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "graspfill/io/ply.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

class PcdTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_pcd" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

ObjectCloud ThreeKinds() {
  ObjectCloud c;
  c.points_G = {{0.01f, 0.02f, 0.03f}, {-0.04f, 0.05f, 0.06f}, {0.07f, -0.08f, 0.09f}};
  c.normals_G = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
  c.provenance = {Provenance::kObserved, Provenance::kSurface, Provenance::kSymmetry};
  c.confidence = {1.0f, 0.6f, 0.75f};
  c.utime = 1234567;
  c.seq = 9;
  c.T_C_G =
      Eigen::Translation3d(0.1, -0.2, 0.6) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  return c;
}

TEST_F(PcdTest, OpenThreeDReadsEveryField) {
  const ObjectCloud c = ThreeKinds();
  WriteCloudPcd(Path("c.pcd"), c);

  open3d::t::geometry::PointCloud t;
  ASSERT_TRUE(open3d::t::io::ReadPointCloud(Path("c.pcd"), t));
  ASSERT_EQ(t.GetPointPositions().GetLength(), 3);
  ASSERT_TRUE(t.HasPointAttr("provenance"));
  ASSERT_TRUE(t.HasPointAttr("confidence"));
  const auto positions = t.GetPointPositions().To(open3d::core::Float32);
  const auto normals = t.GetPointNormals().To(open3d::core::Float32);
  const auto provenance = t.GetPointAttr("provenance").To(open3d::core::Int32);
  const auto confidence = t.GetPointAttr("confidence").To(open3d::core::Float32);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(positions[i][k].Item<float>(), c.points_G[i][k]) << i;
      EXPECT_EQ(normals[i][k].Item<float>(), c.normals_G[i][k]) << i;
    }
    EXPECT_EQ(provenance[i].Item<int>(), static_cast<int>(c.provenance[i])) << i;
    EXPECT_EQ(confidence[i].Item<float>(), c.confidence[i]) << i;
  }

  // The legacy reader (what o3d.io.read_point_cloud uses) sees the points
  // and the provenance's colours in `rgb`.
  open3d::geometry::PointCloud legacy;
  ASSERT_TRUE(open3d::io::ReadPointCloud(Path("c.pcd"), legacy));
  ASSERT_EQ(legacy.points_.size(), 3u);
  ASSERT_EQ(legacy.colors_.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Rgb8 rgb = ProvenanceColor(c.provenance[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(legacy.colors_[i][k] * 255.0, rgb[k], 0.5) << i;
  }
}

TEST_F(PcdTest, ViewpointIsTheCameraInTheGripperFrame) {
  const ObjectCloud c = ThreeKinds();
  WriteCloudPcd(Path("c.pcd"), c);
  std::istringstream header(Bytes(Path("c.pcd")));
  std::string line;
  double t[3] = {}, q[4] = {};
  bool found = false;
  while (std::getline(header, line) && line != "DATA binary") {
    if (line.rfind("VIEWPOINT ", 0) == 0) {
      std::istringstream v(line.substr(10));
      found = static_cast<bool>(v >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >> q[2] >> q[3]);
    }
  }
  ASSERT_TRUE(found);
  const Eigen::Isometry3d T_G_C = c.T_C_G.inverse();
  EXPECT_LT((Eigen::Vector3d(t[0], t[1], t[2]) - T_G_C.translation()).norm(), 1e-12);
  const Eigen::Quaterniond q_G_C(q[0], q[1], q[2], q[3]);
  EXPECT_LT((q_G_C.toRotationMatrix() - T_G_C.rotation()).norm(), 1e-12);
}

TEST_F(PcdTest, SameCloudSameBytesAndAnEmptyCloudIsAFile) {
  WriteCloudPcd(Path("a.pcd"), ThreeKinds());
  WriteCloudPcd(Path("b.pcd"), ThreeKinds());
  EXPECT_EQ(Bytes(Path("a.pcd")), Bytes(Path("b.pcd")));

  ObjectCloud bare;  // no normals, provenance or confidence
  bare.points_G = {{1, 2, 3}};
  WriteCloudPcd(Path("bare.pcd"), bare);
  open3d::t::geometry::PointCloud t;
  ASSERT_TRUE(open3d::t::io::ReadPointCloud(Path("bare.pcd"), t));
  EXPECT_EQ(t.GetPointPositions().GetLength(), 1);
  EXPECT_FALSE(t.HasPointAttr("confidence"));
  EXPECT_FALSE(t.HasPointNormals());

  // An empty model is still a file, header only (Open3D 0.16 refuses to
  // read POINTS 0, so only the bytes are checked).
  WriteCloudPcd(Path("empty.pcd"), ObjectCloud{});
  const std::string empty = Bytes(Path("empty.pcd"));
  EXPECT_NE(empty.find("\nWIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA binary\n"),
            std::string::npos)
      << empty;
  EXPECT_EQ(empty.back(), '\n');
}

TEST_F(PcdTest, FieldsNotOnePerPointAreRefusedAndNothingIsWritten) {
  ObjectCloud c = ThreeKinds();
  c.confidence.pop_back();
  try {
    WriteCloudPcd(Path("bad.pcd"), c);
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("confidence: not one value per point"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(Path("bad.pcd")));
}

// The name decides the bytes: .ply and .pcd (any case), anything else is
// refused before a byte is written; a .pcd given to read is refused with
// what to do.
TEST_F(PcdTest, TheExtensionDecidesTheFormat) {
  const ObjectCloud c = ThreeKinds();
  WriteCloudFile(Path("c.PCD"), c);
  EXPECT_EQ(Bytes(Path("c.PCD")).rfind("# .PCD v0.7", 0), 0u);
  WriteCloudFile(Path("c.ply"), c);
  EXPECT_EQ(Bytes(Path("c.ply")).rfind("ply\n", 0), 0u);
  EXPECT_EQ(ReadCloudFile(Path("c.ply")).size(), 3u);
  for (const char* name : {"c.xyz", "c"}) {
    EXPECT_THROW(WriteCloudFile(Path(name), c), std::invalid_argument) << name;
    EXPECT_FALSE(fs::exists(Path(name))) << name;
  }
  try {
    ReadCloudFile(Path("c.PCD"));
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("give the cloud as .ply"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace graspfill::io
