// SPDX-License-Identifier: BSD-3-Clause
// The mesh reader on the gripper assets: each Robotiq link's COLLADA visual
// mesh and its STL collision mesh come from the same CAD part, so their
// bounds agree once COLLADA's unit and up axis are honoured.
#include "graspfill/claw/mesh_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

const std::string kRobotiq = GRASPFILL_SOURCE_DIR "/../shared/assets/grippers/robotiq_3f";

Eigen::AlignedBox3f Bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v);
  return box;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MeshFileTest, ColladaAndStlOfTheSameLinkAgree) {
  if (!fs::is_directory(kRobotiq)) GTEST_SKIP() << "gripper assets not found at " << kRobotiq;
  for (const std::string link : {"palm", "link_0", "link_1", "link_2", "link_3"}) {
    const Eigen::AlignedBox3f dae = Bounds(ReadMeshFile(kRobotiq + "/visual/" + link + ".dae"));
    const Eigen::AlignedBox3f stl = Bounds(ReadMeshFile(kRobotiq + "/collision/" + link + ".STL"));
    // Visual and collision meshes differ in detail, not in extent.
    EXPECT_LT((dae.min() - stl.min()).cwiseAbs().maxCoeff(), 5e-4f) << link;
    EXPECT_LT((dae.max() - stl.max()).cwiseAbs().maxCoeff(), 5e-4f) << link;
  }
  // STL's three vertices per triangle are merged.
  const TriangleMesh palm = ReadMeshFile(kRobotiq + "/collision/palm.STL");
  EXPECT_LT(palm.vertices.size(), 3 * palm.triangles.size() / 2);
}

TEST(MeshFileTest, ColladaUnitAndUpAxisAreApplied) {
  if (!fs::is_directory(kRobotiq)) GTEST_SKIP() << "gripper assets not found at " << kRobotiq;
  const std::string text = ReadAll(kRobotiq + "/visual/link_1.dae");
  ASSERT_NE(text.find("<unit name=\"meter\" meter=\"1\"/>"), std::string::npos);
  ASSERT_NE(text.find("<up_axis>Z_UP</up_axis>"), std::string::npos);
  const fs::path dir = fs::path(::testing::TempDir()) / "mesh_file_collada";
  fs::create_directories(dir);
  // The same geometry declared in millimetres, and declared Y-up.
  std::string mm = text;
  mm.replace(mm.find("meter=\"1\""), 9, "meter=\"0.001\"");
  std::ofstream(dir / "mm.dae") << mm;
  std::string y_up = text;
  y_up.replace(y_up.find("Z_UP"), 4, "Y_UP");
  std::ofstream(dir / "y_up.dae") << y_up;
  const Eigen::AlignedBox3f m = Bounds(ReadMeshFile(kRobotiq + "/visual/link_1.dae"));
  const Eigen::AlignedBox3f mm_box = Bounds(ReadMeshFile((dir / "mm.dae").string()));
  const Eigen::AlignedBox3f y_box = Bounds(ReadMeshFile((dir / "y_up.dae").string()));
  fs::remove_all(dir);
  EXPECT_LT((mm_box.min() - 0.001f * m.min()).cwiseAbs().maxCoeff(), 1e-7f);
  EXPECT_LT((mm_box.max() - 0.001f * m.max()).cwiseAbs().maxCoeff(), 1e-7f);
  // Y-up content turned so its y is +z: (x, y, z) -> (x, -z, y).
  EXPECT_NEAR(y_box.min().x(), m.min().x(), 1e-6f);
  EXPECT_NEAR(y_box.min().y(), -m.max().z(), 1e-6f);
  EXPECT_NEAR(y_box.max().y(), -m.min().z(), 1e-6f);
  EXPECT_NEAR(y_box.min().z(), m.min().y(), 1e-6f);
  EXPECT_NEAR(y_box.max().z(), m.max().y(), 1e-6f);
}

TEST(MeshFileTest, UnreadableFilesAreErrorsNamingThem) {
  const fs::path dir = fs::path(::testing::TempDir()) / "mesh_file_errors";
  fs::create_directories(dir);
  std::ofstream(dir / "junk.stl") << "this is not a mesh";
  for (const std::string name : {"junk.stl", "missing.obj"}) {
    try {
      ReadMeshFile((dir / name).string());
      ADD_FAILURE() << name << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace graspfill::claw
