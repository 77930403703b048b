// SPDX-License-Identifier: BSD-3-Clause
// PLY clouds and mesh files: round trips, determinism, errors naming the
// path.
#include "graspfill/io/ply.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "file_size_limit.hpp"
#include "graspfill/core/provenance_colors.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

class PlyIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(GRASPFILL_BINARY_DIR) / "test_tmp" / "io_ply" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

ObjectCloud SomeCloud(bool normals) {
  ObjectCloud cloud;
  cloud.utime = 1700000000000001;
  cloud.seq = 42;
  cloud.frame_name = "gripper";
  cloud.T_C_G.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  cloud.T_C_G.translation() = Eigen::Vector3d(0.01, 0.2, 0.9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(-0.1f, 0.1f);
  for (int i = 0; i < 257; ++i) {
    cloud.points_G.emplace_back(coord(rng), coord(rng), coord(rng));
    if (normals) cloud.normals_G.push_back(cloud.points_G.back().normalized());
    cloud.provenance.push_back(static_cast<Provenance>((i * 7) % 3));
  }
  return cloud;
}

TEST_F(PlyIoTest, CloudRoundTripKeepsPointsNormalsProvenanceAndPose) {
  const ObjectCloud cloud = SomeCloud(true);
  WriteCloudPly(Path("cloud.ply"), cloud);
  const ObjectCloud back = ReadCloudPly(Path("cloud.ply"));
  EXPECT_EQ(back.points_G, cloud.points_G);
  EXPECT_EQ(back.normals_G, cloud.normals_G);
  EXPECT_EQ(back.provenance, cloud.provenance);
  EXPECT_EQ(back.utime, cloud.utime);
  EXPECT_EQ(back.seq, cloud.seq);
  EXPECT_EQ(back.frame_name, cloud.frame_name);
  // %.17g round-trips doubles; the quaternion detour costs rounding only.
  EXPECT_TRUE(back.T_C_G.matrix().isApprox(cloud.T_C_G.matrix(), 1e-12));

  const std::string bytes = ReadBytes(Path("cloud.ply"));
  EXPECT_NE(bytes.find("format binary_little_endian 1.0\n"), std::string::npos);
  EXPECT_NE(bytes.find("property float nx\n"), std::string::npos);
  EXPECT_NE(bytes.find("property uchar provenance\nproperty uchar red\nproperty uchar green\n"
                       "property uchar blue\nend_header\n"),
            std::string::npos);
  // 257 vertices of 6 floats + 4 bytes after the header.
  const size_t header = bytes.find("end_header\n") + 11;
  EXPECT_EQ(bytes.size() - header, 257u * 28u);
}

TEST_F(PlyIoTest, CloudWithoutNormalsOrProvenance) {
  ObjectCloud cloud = SomeCloud(false);
  cloud.provenance.clear();
  WriteCloudPly(Path("bare.ply"), cloud);
  const ObjectCloud back = ReadCloudPly(Path("bare.ply"));
  EXPECT_EQ(back.points_G, cloud.points_G);
  EXPECT_TRUE(back.normals_G.empty());
  EXPECT_EQ(back.provenance, std::vector<Provenance>(257, Provenance::kObserved));
}

TEST_F(PlyIoTest, ConfidenceRoundTripsAndIsChecked) {
  ObjectCloud cloud = SomeCloud(false);
  for (size_t i = 0; i < cloud.size(); ++i) cloud.confidence.push_back(static_cast<float>(i % 11) / 10.0f);
  WriteCloudPly(Path("conf.ply"), cloud);
  EXPECT_NE(ReadBytes(Path("conf.ply")).find("property uchar provenance\nproperty float confidence\n"),
            std::string::npos);
  const ObjectCloud back = ReadCloudPly(Path("conf.ply"));
  EXPECT_EQ(back.confidence, cloud.confidence);
  EXPECT_EQ(back.provenance, cloud.provenance);
  cloud.confidence.pop_back();
  EXPECT_THROW(WriteCloudPly(Path("short.ply"), cloud), std::runtime_error);
  // Without the property the cloud has none.
  cloud.confidence.clear();
  WriteCloudPly(Path("none.ply"), cloud);
  EXPECT_TRUE(ReadCloudPly(Path("none.ply")).confidence.empty());
}

// Viewers that know nothing of `provenance` (Open3D, MeshLab) show the
// provenance's colour; the header names the version that wrote the file.
TEST_F(PlyIoTest, ColoursByProvenanceAndVersionComment) {
  const ObjectCloud cloud = SomeCloud(false);
  WriteCloudPly(Path("rgb.ply"), cloud);
  open3d::geometry::PointCloud o3d;
  ASSERT_TRUE(open3d::io::ReadPointCloud(Path("rgb.ply"), o3d));
  ASSERT_EQ(o3d.colors_.size(), cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Rgb8 expected = ProvenanceColor(cloud.provenance[i]);
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(std::lround(o3d.colors_[i][k] * 255.0), expected[k]) << "point " << i;
    }
  }
  // The three colours differ, so a viewer tells the provenances apart.
  EXPECT_NE(ProvenanceColor(Provenance::kObserved), ProvenanceColor(Provenance::kSurface));
  EXPECT_NE(ProvenanceColor(Provenance::kObserved), ProvenanceColor(Provenance::kSymmetry));
  EXPECT_NE(ProvenanceColor(Provenance::kSurface), ProvenanceColor(Provenance::kSymmetry));
  // The provenance property still reads back as it was written.
  EXPECT_EQ(ReadCloudPly(Path("rgb.ply")).provenance, cloud.provenance);
  const std::string bytes = ReadBytes(Path("rgb.ply"));
  const std::string header = bytes.substr(0, bytes.find("end_header\n"));
  EXPECT_NE(header.find("\ncomment graspfill software graspfill " GRASPFILL_PROJECT_VERSION "\n"),
            std::string::npos)
      << header;
}

TEST_F(PlyIoTest, SameCloudGivesSameBytes) {
  const ObjectCloud cloud = SomeCloud(true);
  WriteCloudPly(Path("a.ply"), cloud);
  WriteCloudPly(Path("b.ply"), cloud);
  EXPECT_EQ(ReadBytes(Path("a.ply")), ReadBytes(Path("b.ply")));
}

TEST_F(PlyIoTest, ZeroPointsAreWrittenAndReadBack) {
  ObjectCloud empty;
  WriteCloudPly(Path("empty.ply"), empty);
  const ObjectCloud back = ReadCloudPly(Path("empty.ply"));
  EXPECT_EQ(back.size(), 0u);
  EXPECT_TRUE(back.provenance.empty());
}

TEST_F(PlyIoTest, ForeignPlyWithoutProvenanceIsObserved) {
  WriteText(Path("ascii.ply"),
            "ply\nformat ascii 1.0\nelement vertex 2\n"
            "property double x\nproperty double y\nproperty double z\n"
            "end_header\n0 0 0\n0.5 -0.25 1\n");
  const ObjectCloud back = ReadCloudPly(Path("ascii.ply"));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.points_G[1], Eigen::Vector3f(0.5f, -0.25f, 1.0f));
  EXPECT_EQ(back.provenance, std::vector<Provenance>(2, Provenance::kObserved));
  EXPECT_EQ(back.frame_name, "gripper");  // ObjectCloud's default
}

TEST_F(PlyIoTest, ReadErrorsNameThePath) {
  const std::string missing = Path("missing.ply");
  try {
    ReadCloudPly(missing);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos);
  }
  WriteText(Path("garbage.ply"), "this is not a ply file\n");
  try {
    ReadCloudPly(Path("garbage.ply"));
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(Path("garbage.ply")), std::string::npos) << e.what();
  }
  WriteText(Path("badprov.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property uchar provenance\nend_header\n0 0 0 3\n");
  EXPECT_THROW(ReadCloudPly(Path("badprov.ply")), std::runtime_error);
}

TEST_F(PlyIoTest, WriteErrorsNameThePath) {
  const std::string bad = Path("no/such/dir/cloud.ply");
  try {
    WriteCloudPly(bad, SomeCloud(true));
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  ObjectCloud inconsistent = SomeCloud(true);
  inconsistent.normals_G.pop_back();
  EXPECT_THROW(WriteCloudPly(Path("x.ply"), inconsistent), std::runtime_error);
}

// A full disk while writing (RLIMIT_FSIZE, see file_size_limit.hpp) used
// to truncate the good file and say only "write failed".
TEST_F(PlyIoTest, FullDiskKeepsThePreviousFileAndNamesTheReason) {
  WriteText(Path("cloud.ply"), "the previous good cloud");
  std::string error;
  {
    testing::FileSizeLimit full(1024);  // the cloud is ~6 KB
    ASSERT_TRUE(full.ok());
    try {
      WriteCloudPly(Path("cloud.ply"), SomeCloud(true));
      ADD_FAILURE() << "no throw";
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
  }
  EXPECT_NE(error.find("cannot write PLY '" + Path("cloud.ply") + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(std::strerror(EFBIG)), std::string::npos) << error;
  EXPECT_EQ(ReadBytes(Path("cloud.ply")), "the previous good cloud");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1)
      << "a temporary file was left behind";
  // With room, the same write replaces it.
  WriteCloudPly(Path("cloud.ply"), SomeCloud(true));
  EXPECT_EQ(ReadCloudPly(Path("cloud.ply")).size(), SomeCloud(true).size());
}

TriangleMesh Tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

TEST_F(PlyIoTest, MeshRoundTrip) {
  const TriangleMesh mesh = Tetrahedron();
  WriteMeshPly(Path("tet.ply"), mesh);
  const TriangleMesh back = ReadMesh(Path("tet.ply"));
  EXPECT_EQ(back.vertices, mesh.vertices);
  EXPECT_EQ(back.triangles, mesh.triangles);
  WriteMeshPly(Path("tet2.ply"), mesh);
  EXPECT_EQ(ReadBytes(Path("tet.ply")), ReadBytes(Path("tet2.ply")));

  TriangleMesh bad = mesh;
  bad.triangles.push_back({0, 1, 4});
  EXPECT_THROW(WriteMeshPly(Path("bad.ply"), bad), std::runtime_error);
}

TEST_F(PlyIoTest, ReadsObjAndStl) {
  WriteText(Path("quad.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  const TriangleMesh obj = ReadMesh(Path("quad.obj"));
  EXPECT_EQ(obj.triangles.size(), 2u);
  EXPECT_GE(obj.vertices.size(), 4u);

  WriteText(Path("tri.stl"),
            "solid t\n facet normal 0 0 1\n  outer loop\n"
            "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
            "  endloop\n endfacet\nendsolid t\n");
  const TriangleMesh stl = ReadMesh(Path("tri.stl"));
  ASSERT_EQ(stl.triangles.size(), 1u);
  // Whatever the reader's vertex order, the triangle spans these corners.
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (int k = 0; k < 3; ++k) sum += stl.vertices[stl.triangles[0][k]];
  EXPECT_TRUE(sum.isApprox(Eigen::Vector3f(1, 1, 0)));
}

TEST_F(PlyIoTest, ReadMeshErrors) {
  const std::string missing = Path("missing.stl");
  try {
    ReadMesh(missing);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  WriteMeshPly(Path("empty.ply"), TriangleMesh{});
  try {
    ReadMesh(Path("empty.ply"));
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(Path("empty.ply")), std::string::npos) << e.what();
  }
  WriteText(Path("garbage.obj"), "\x01\x02 not a mesh");
  EXPECT_THROW(ReadMesh(Path("garbage.obj")), std::runtime_error);
}

// ---- Issue 12: malformed PLY files are clear errors, never crashes or
// silent garbage -------------------------------------------------------------

// The message of what `read` throws (fails the test if it does not throw).
std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}

TEST_F(PlyIoTest, HeaderCutInsideALineIsAnErrorNotASegfault) {
  // The 40-byte file: Open3D's reader segfaulted on it.
  const std::string path = Path("cut.ply");
  WriteText(path, std::string("ply\nformat ascii 1.0\nobj_info").append(40 - 29, 'x'));
  ASSERT_EQ(std::filesystem::file_size(path), 40u);
  const std::string cloud_error = ErrorOf([&] { ReadCloudPly(path); });
  EXPECT_NE(cloud_error.find("cannot read PLY '" + path + "'"), std::string::npos) << cloud_error;
  EXPECT_NE(cloud_error.find("without 'end_header'"), std::string::npos) << cloud_error;
  const std::string mesh_error = ErrorOf([&] { ReadMesh(path); });
  EXPECT_NE(mesh_error.find("cannot read mesh '" + path + "'"), std::string::npos) << mesh_error;
}

TEST_F(PlyIoTest, MissingCoordinateIsNamed) {
  // Open3D read this with z = 0.
  WriteText(Path("noz.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\n"
            "property float x\nproperty float y\nend_header\n1 2\n");
  const std::string error = ErrorOf([&] { ReadCloudPly(Path("noz.ply")); });
  EXPECT_NE(error.find(Path("noz.ply")), std::string::npos) << error;
  EXPECT_NE(error.find("no 'z' vertex property"), std::string::npos) << error;
}

TEST_F(PlyIoTest, BinaryHeaderOverAsciiBodyIsRefused) {
  // Open3D read the text as floats.
  WriteText(Path("mixed.ply"),
            "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n"
            "0.1 0.2 0.3\n0.4 0.5 0.6\n");
  const std::string error = ErrorOf([&] { ReadCloudPly(Path("mixed.ply")); });
  EXPECT_NE(error.find(Path("mixed.ply")), std::string::npos) << error;
  EXPECT_NE(error.find("does not match the binary header"), std::string::npos) << error;
}

TEST_F(PlyIoTest, CountsBeyondTheFileAndBadValuesAreNamed) {
  WriteText(Path("huge.ply"),
            "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n");
  std::string error = ErrorOf([&] { ReadCloudPly(Path("huge.ply")); });
  EXPECT_NE(error.find("element 'vertex' declares 4000000000 entries"), std::string::npos) << error;
  WriteText(Path("short.ply"),
            "ply\nformat ascii 1.0\nelement vertex 2\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5\n");
  error = ErrorOf([&] { ReadCloudPly(Path("short.ply")); });
  EXPECT_NE(error.find("vertex 1, property 'z'"), std::string::npos) << error;
  WriteText(Path("word.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n1 abc 3\n");
  error = ErrorOf([&] { ReadCloudPly(Path("word.ply")); });
  EXPECT_NE(error.find("vertex 0, property 'y': 'abc' is not a number"), std::string::npos) << error;
  WriteText(Path("inf.ply"),
            "ply\nformat ascii 1.0\nelement vertex 1\n"
            "property double x\nproperty double y\nproperty double z\nend_header\n1 1e300 3\n");
  error = ErrorOf([&] { ReadCloudPly(Path("inf.ply")); });
  EXPECT_NE(error.find("vertex 0, property 'y'"), std::string::npos) << error;
}

TEST_F(PlyIoTest, BinaryBigEndianAndExtraElementsAreRead) {
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\n"
      "property float x\nproperty float y\nproperty float z\n"
      "element extra 1\nproperty list uchar int stuff\nend_header\n";
  for (float v : {1.0f, -2.0f, 0.5f}) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int i = 3; i >= 0; --i) bytes.push_back(static_cast<char>(bits >> (8 * i)));
  }
  bytes.push_back(1);
  bytes.append(4, '\0');
  WriteText(Path("be.ply"), bytes);
  const ObjectCloud cloud = ReadCloudPly(Path("be.ply"));
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.points_G[0], Eigen::Vector3f(1.0f, -2.0f, 0.5f));
}

TEST_F(PlyIoTest, MeshPolygonsAreFannedAndBadFacesNamed) {
  // A quad and a pentagon (Open3D's ear clipping crashed on such a mesh
  // with collinear or repeated vertices), and a degenerate triangle.
  WriteText(Path("poly.ply"),
            "ply\nformat ascii 1.0\nelement vertex 5\n"
            "property float x\nproperty float y\nproperty float z\n"
            "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 0\n"
            "4 0 1 2 3\n5 0 1 1 2 3\n3 0 0 1\n");
  const TriangleMesh mesh = ReadMesh(Path("poly.ply"));
  EXPECT_EQ(mesh.vertices.size(), 5u);
  EXPECT_EQ(mesh.triangles.size(), 4u);  // 2 + 2 (one of the pentagon's 3 is degenerate) + 0
  WriteText(Path("badindex.ply"),
            "ply\nformat ascii 1.0\nelement vertex 3\n"
            "property float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0\n3 0 1 7\n");
  const std::string error = ErrorOf([&] { ReadMesh(Path("badindex.ply")); });
  EXPECT_NE(error.find("face 0, property 'vertex_indices': vertex index 7 out of range"), std::string::npos)
      << error;
}

}  // namespace
}  // namespace graspfill::io
