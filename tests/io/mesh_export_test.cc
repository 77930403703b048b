// SPDX-License-Identifier: BSD-3-Clause
// WriteMesh: each format read back by Open3D gives the mesh written; an
// unknown extension or a bad index is refused; the bytes are the same twice.
#include "graspfill/io/mesh_export.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace graspfill::io {
namespace {

// A tetrahedron, outward-facing.
TriangleMesh Tetrahedron() {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.02f, 0}, {0, 0, 0.03f}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

std::string Dir() {
  const std::filesystem::path dir =
      std::filesystem::path(GRASPFILL_BINARY_DIR) / "test_scratch" / "mesh_export";
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MeshExport, FormatFromExtension) {
  EXPECT_EQ(MeshFormatOf("a/b.ply"), MeshFormat::kPly);
  EXPECT_EQ(MeshFormatOf("B.STL"), MeshFormat::kStl);
  EXPECT_EQ(MeshFormatOf("c.Obj"), MeshFormat::kObj);
  EXPECT_FALSE(MeshFormatOf("d.off"));
  EXPECT_FALSE(MeshFormatOf("ply"));
}

TEST(MeshExport, EachFormatReadsBackAsWritten) {
  const TriangleMesh m = Tetrahedron();
  for (const char* ext : {"ply", "stl", "obj"}) {
    const std::string path = Dir() + "/tet." + ext;
    WriteMesh(path, m);
    open3d::geometry::TriangleMesh o;
    ASSERT_TRUE(open3d::io::ReadTriangleMesh(path, o)) << path;
    o.RemoveDuplicatedVertices();  // STL repeats vertices per triangle
    ASSERT_EQ(o.triangles_.size(), 4u) << ext;
    ASSERT_EQ(o.vertices_.size(), 4u) << ext;
    EXPECT_TRUE(o.IsWatertight()) << ext;
    // Same triangles, same winding: the signed volume is the tetrahedron's.
    double volume = 0.0;
    for (const Eigen::Vector3i& t : o.triangles_) {
      volume += o.vertices_[t[0]].dot(o.vertices_[t[1]].cross(o.vertices_[t[2]])) / 6.0;
    }
    EXPECT_NEAR(volume, 0.01 * 0.02 * 0.03 / 6.0, 1e-12) << ext;
    const std::string first = ReadBytes(path);
    WriteMesh(path, m);
    EXPECT_EQ(ReadBytes(path), first) << ext;
  }
  // STL's normals: the first face (0, 2, 1) lies in z = 0 and faces -z.
  const std::string stl = ReadBytes(Dir() + "/tet.stl");
  ASSERT_EQ(stl.size(), 84u + 4 * 50);
  float n[3];
  std::memcpy(n, stl.data() + 84, sizeof(n));
  EXPECT_FLOAT_EQ(n[2], -1.0f);
}

TEST(MeshExport, RefusesUnknownExtensionsAndBadIndices) {
  try {
    WriteMesh(Dir() + "/tet.off", Tetrahedron());
    FAIL() << "unknown extension accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown extension"), std::string::npos) << e.what();
  }
  TriangleMesh bad = Tetrahedron();
  bad.triangles[1][2] = 4;
  EXPECT_THROW(WriteMesh(Dir() + "/bad.stl", bad), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(Dir() + "/bad.stl"));
}

}  // namespace
}  // namespace graspfill::io
