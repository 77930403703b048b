// SPDX-License-Identifier: BSD-3-Clause
// Issue 12: claw meshes are checked at load. Each case below was accepted
// before (and failed later, in the ray caster at the first gripper state,
// with no file named, or not at all); now the load fails naming the
// description, the link and the mesh file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "graspfill/claw/claw_mask.hpp"
#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

class ClawValidationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::path(::testing::TempDir()) /
        ("claw_validation_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  // An ASCII PLY with these vertices and triangles.
  std::string Ply(const std::string& name, const std::string& vertices, int num_vertices,
                  const std::string& faces, int num_faces) {
    return Write(name, "ply\nformat ascii 1.0\nelement vertex " + std::to_string(num_vertices) +
                           "\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face " +
                           std::to_string(num_faces) +
                           "\nproperty list uchar int vertex_indices\nend_header\n" + vertices + faces);
  }
  // A two-link description whose finger link uses `mesh`.
  std::string Description(const std::string& mesh) {
    Write("tet.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    return Write("claw.json", R"({"name": "test", "links": [
        {"name": "palm", "mesh": "tet.obj"},
        {"name": "finger", "parent": "palm", "mesh": ")" +
                                  mesh + R"("}]})");
  }
  // Load must fail with every one of `parts` in the message.
  void ExpectLoadError(const std::string& description, std::initializer_list<std::string> parts) {
    try {
      ClawModel::Load(description);
      ADD_FAILURE() << "loaded without an error";
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      for (const std::string& part : parts) {
        EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
      }
    }
  }

  fs::path dir_;
};

const char* kTetVertices = "0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n";

TEST_F(ClawValidationTest, FaceIndexOutOfRangeNamesFileAndLink) {
  Ply("bad_index.ply", kTetVertices, 4, "3 0 2 1\n3 0 1 1000000\n", 2);
  const std::string description = Description("bad_index.ply");
  ExpectLoadError(description, {description, "(finger)", "bad_index.ply", "out of range"});
}

TEST_F(ClawValidationTest, NanVertexNamesFileAndLink) {
  Ply("nan.ply", "0 0 0\nnan 0 0\n0 0.1 0\n0 0 0.1\n", 4, "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", 4);
  const std::string description = Description("nan.ply");
  ExpectLoadError(description, {description, "(finger)", "nan.ply", "not finite"});
}

TEST_F(ClawValidationTest, DegenerateTrianglesAreDroppedAndCounted) {
  // The tetrahedron plus a repeated-index face and a collinear one.
  Write("degenerate.obj",
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nv 0.2 0 0\n"
        "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 2\nf 1 2 5\n");
  const ClawModel model = ClawModel::Load(Description("degenerate.obj"));
  ASSERT_EQ(model.links().size(), 2u);
  const Link& finger = model.links()[1];
  EXPECT_EQ(finger.name, "finger");
  EXPECT_EQ(finger.degenerate_triangles_dropped, 2);
  EXPECT_EQ(finger.mesh.triangles.size(), 4u);
  EXPECT_EQ(model.links()[0].degenerate_triangles_dropped, 0);
}

TEST_F(ClawValidationTest, AllDegenerateMeshIsAnError) {
  Write("flat.obj", "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nf 1 2 3\n");
  const std::string description = Description("flat.obj");
  ExpectLoadError(description, {description, "(finger)", "flat.obj", "zero area"});
}

TEST_F(ClawValidationTest, MissingMeshNamesFileAndLink) {
  const std::string description = Description("nope.stl");
  ExpectLoadError(description, {description, "(finger)", "nope.stl", "not found"});
}

// Found by fuzz_claw (tests/fuzz/regressions/claw/json_number_overflow):
// a number past double's range escaped as nlohmann's out_of_range, no file named.
TEST_F(ClawValidationTest, NumberOverflowIsBadJsonNamingTheFile) {
  const std::string description = Write("overflow.json", R"({"name": "x", "links": 1e999})");
  ExpectLoadError(description, {description, "bad JSON"});
}

// A model built in code is checked when it is built, not when the mask
// first casts rays against it.
TEST(ClawModelValidationTest, ConstructorRejectsBadMeshes) {
  Link palm;
  palm.name = "palm";
  palm.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  palm.mesh.triangles = {{0, 1, 2}};
  Link bad = palm;
  bad.name = "bad_finger";
  bad.parent = 0;
  bad.mesh.triangles.push_back({0, 1, 1000000});
  try {
    ClawModel("test", {palm, bad});
    ADD_FAILURE() << "accepted a triangle index out of range";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bad_finger"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  Link nan = palm;
  nan.name = "nan_finger";
  nan.parent = 0;
  nan.mesh.vertices[1].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(ClawModel("test", {palm, nan}), std::invalid_argument);
  // The good one still builds and masks.
  const ClawModel good("test", {palm});
  ClawMask mask;
  EXPECT_NO_THROW(mask.SetClaw(good.Posed(0.0)));
}

}  // namespace
}  // namespace graspfill::claw
