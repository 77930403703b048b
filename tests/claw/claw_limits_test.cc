// SPDX-License-Identifier: BSD-3-Clause
// Issue 36: claw geometry within the limits of claw_limits.hpp, in every
// claw source. Each case below was accepted before (a claw 1e6 m wide, an
// rpy of 1e300, a mesh scaled by 1e30) or ended in an allocator's words
// ("cannot create std::vector larger than max_size()"); now the load fails
// naming the file, the field or link, the value and the limit. Also: a
// claw without geometry (xacro saved as .urdf), too many links or
// triangles, a FIFO or device as a mesh.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

class ClawLimitsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("claw_limits_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
    // A 5 cm tetrahedron, outward-facing.
    Write("tet.obj",
          "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  // A description: a palm with the tetrahedron, and a finger whose JSON
  // object's members (after its name and parent) are `finger`.
  std::string Description(const std::string& finger, const std::string& top = "") {
    return Write("claw.json", R"({"name": "test", )" + top + R"("links": [
        {"name": "palm", "mesh": "tet.obj"},
        {"name": "finger", "parent": "palm", )" +
                                  finger + "}]}");
  }
  std::string PrismaticFinger(const std::string& limits, const std::string& origin = "[0, 0, 0]") {
    return R"("mesh": "tet.obj", "joint": {"type": "prismatic", "origin": {"xyz": )" + origin +
           R"(}, "axis": [1, 0, 0], "limits": )" + limits + R"(, "drive": {"opening_gain": 1.0}})";
  }
  // A URDF: a base link with `base_geometry` (inside <collision>), a
  // finger on a prismatic joint; `extra` goes inside <robot>.
  std::string Urdf(const std::string& base_geometry, const std::string& joint_origin = "0 0 0",
                   const std::string& limit = "lower=\"0\" upper=\"0.04\"", const std::string& extra = "") {
    return Write("claw.urdf", R"(<?xml version="1.0"?>
<robot name="test">
  <link name="base"><collision>)" +
                                  base_geometry + R"(</collision></link>
  <link name="finger"><collision><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="finger"/><origin xyz=")" +
                                  joint_origin + R"("/>
    <axis xyz="1 0 0"/><limit )" + limit +
                                  R"( effort="1" velocity="1"/>
  </joint>)" + extra + R"(
</robot>)");
  }
  void ExpectLoadError(const std::string& path, std::initializer_list<std::string> parts) {
    try {
      ClawModel::Load(path);
      ADD_FAILURE() << "loaded without an error";
    } catch (const std::exception& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      for (const std::string& part : parts) {
        EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
      }
      EXPECT_EQ(message.find("max_size"), std::string::npos) << message;
    }
  }

  fs::path dir_;
};

TEST_F(ClawLimitsTest, TheSameClawWithinTheLimitsLoads) {
  EXPECT_EQ(ClawModel::Load(Description(PrismaticFinger(R"({"lower": 0, "upper": 0.04})"))).links().size(),
            2u);
  EXPECT_EQ(ClawModel::Load(Urdf(R"(<geometry><box size="0.1 0.1 0.02"/></geometry>)")).links().size(), 2u);
}

TEST_F(ClawLimitsTest, DescriptionPosesScalesAndTravelsBeyondTheLimits) {
  ExpectLoadError(Description(R"("mesh": "tet.obj")", R"("T_G_root": {"rpy": [1e300, 0, 0]}, )"),
                  {"T_G_root.rpy[0]: 1e+300 rad is beyond the 12.5664 rad (4 pi) limit"});
  ExpectLoadError(Description(PrismaticFinger(R"({"lower": 0, "upper": 0.04})", "[1e30, 0, 0]")),
                  {"links[1] (finger).joint.origin.xyz[0]: 1e+30 m is beyond the 0.5 m limit"});
  ExpectLoadError(Description(R"("mesh": "tet.obj", "mesh_origin": {"xyz": [0, -0.6, 0]})"),
                  {"links[1] (finger).mesh_origin.xyz[1]: -0.6 m is beyond the 0.5 m limit"});
  ExpectLoadError(Description(R"("mesh": "tet.obj", "mesh_scale": 1e30)"),
                  {"links[1] (finger).mesh_scale: scale 1e+30 is beyond the limit of 1000"});
  // 0.05 m x 11 = 0.55 m: within the scale limit, beyond the reach.
  ExpectLoadError(Description(R"("mesh": "tet.obj", "mesh_scale": 11)"),
                  {"links[1] (finger).mesh", "tet.obj",
                   "lies 0.55 m from the mesh's origin, beyond "
                   "the 0.5 m limit"});
  // Each value within the limit, the chain beyond it: 0.4 m out, 0.3 m of
  // travel, a mesh reaching 0.05 m.
  ExpectLoadError(Description(PrismaticFinger(R"({"lower": 0, "upper": 0.3})", "[0.4, 0, 0]")),
                  {"the claw reaches up to 0.75 m from G's origin (link 'finger'", "beyond the 0.5 m limit"});
  ExpectLoadError(Description(PrismaticFinger(R"({"lower": 0, "upper": 1e12})")),
                  {"links[1] (finger).joint.limits.upper: 1e+12 m is beyond the 0.5 m limit"});
  ExpectLoadError(Description(R"("mesh": "tet.obj", "joint": {"type": "revolute", "axis": [0, 0, 1],
                  "limits": {"lower": -1e9, "upper": 0}, "drive": {"opening_gain": 1}})"),
                  {"links[1] (finger).joint.limits.lower: -1e+09 rad is beyond the 12.5664 rad"});
  ExpectLoadError(Description(R"("mesh": "tet.obj", "joint": {"type": "revolute", "axis": [0, 0, 1],
                  "limits": {"lower": 0, "upper": 1}, "drive": {"joint_index": 2000000000}})"),
                  {"links[1] (finger).joint.drive.joint_index: expected an integer 0..255"});
}

TEST_F(ClawLimitsTest, DescriptionWithoutGeometryOrWithTooManyLinks) {
  ExpectLoadError(Write("frames.json", R"({"links": [{"name": "a"}, {"name": "b", "parent": "a"}]})"),
                  {"links: no link has a mesh"});
  std::string links = R"({"name": "l0", "mesh": "tet.obj"})";
  for (int i = 1; i <= kMaxClawLinks; ++i) {
    links += R"(, {"name": "l)" + std::to_string(i) + R"(", "parent": "l)" + std::to_string(i - 1) + R"("})";
  }
  ExpectLoadError(Write("many.json", R"({"links": [)" + links + "]}"),
                  {"links: 257 links, over the limit of 256 per claw"});
}

TEST_F(ClawLimitsTest, MeshFilesAreRegularFilesWithinTheSizeAndTriangleLimits) {
  // A FIFO (assimp would block opening it) and a device are refused unopened.
  ASSERT_EQ(::mkfifo((dir_ / "fifo.stl").c_str(), 0600), 0);
  ExpectLoadError(Description(R"("mesh": "fifo.stl")"),
                  {"links[1] (finger).mesh", "fifo.stl", "not a regular file"});
  ExpectLoadError(Description(R"("mesh": "/dev/zero")"), {"/dev/zero", "not a regular file"});
  // Over the byte limit: refused before a byte is read (the file is sparse).
  {
    std::ofstream big(dir_ / "big.stl", std::ios::binary);
    big.seekp(kMaxMeshFileBytes);
    big.put('\0');
  }
  ExpectLoadError(Description(R"("mesh": "big.stl")"),
                  {"big.stl", std::to_string(kMaxMeshFileBytes + 1) + " bytes, over the limit of " +
                                  std::to_string(kMaxMeshFileBytes)});
  // One face more than the claw may have, in 8 MB of OBJ: refused once
  // assimp has counted them, before the vertices are merged.
  {
    std::ofstream obj(dir_ / "many.obj");
    obj << "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\n";
    for (int64_t i = 0; i <= kMaxClawTriangles; ++i) obj << "f 1 2 3\n";
  }
  ExpectLoadError(
      Description(R"("mesh": "many.obj")"),
      {"many.obj", std::to_string(kMaxClawTriangles + 1) + " triangles, over the claw's limit of " +
                       std::to_string(kMaxClawTriangles)});
}

TEST_F(ClawLimitsTest, UrdfGeometryAndJointsBeyondTheLimits) {
  ExpectLoadError(Urdf(R"(<geometry><box size="1e6 0.01 0.01"/></geometry>)"),
                  {"link 'base': collision box size[0]: 1e+06 m is beyond the 0.5 m limit"});
  ExpectLoadError(Urdf(R"(<geometry><sphere radius="0.6"/></geometry>)"),
                  {"link 'base': collision sphere radius: 0.6 m is beyond the 0.5 m limit"});
  // Within each limit, beyond the reach: a 0.4 m cube's corner is 0.35 m
  // out, the finger 0.45 m out on its joint.
  ExpectLoadError(Urdf(R"(<geometry><box size="0.4 0.4 0.4"/></geometry>)", "0.45 0 0"),
                  {"the claw reaches up to", "(link 'finger'", "beyond the 0.5 m limit"});
  ExpectLoadError(Urdf(R"(<geometry><cylinder radius="0.01" length="0"/></geometry>)"),
                  {"link 'base': collision cylinder length: 0 m: must be more than 0"});
  ExpectLoadError(Urdf(R"(<geometry><mesh filename="tet.obj" scale="1e30 1e30 1e30"/></geometry>)"),
                  {"link 'base': collision mesh: scale 1e+30 is beyond the limit of 1000"});
  ExpectLoadError(
      Urdf(R"(<origin xyz="0 0 0" rpy="0 1e300 0"/><geometry><box size="0.1 0.1 0.1"/></geometry>)"),
      {"line 3: rpy[1]: 1e+300 rad is beyond the 12.5664 rad (4 pi) limit"});
  ExpectLoadError(Urdf(R"(<origin xyz="0 0 -1e30"/><geometry><box size="0.1 0.1 0.1"/></geometry>)"),
                  {"link 'base': collision origin xyz[2]: -1e+30 m is beyond the 0.5 m limit"});
  const std::string box = R"(<geometry><box size="0.1 0.1 0.1"/></geometry>)";
  ExpectLoadError(Urdf(box, "1e30 0 0"), {"joint 'slide': origin xyz[0]: 1e+30 m is beyond the 0.5 m limit"});
  ExpectLoadError(Urdf(box, "0 0 0", R"(lower="-1e12" upper="1e12")"),
                  {"joint 'slide': lower limit: -1e+12 m is beyond the 0.5 m limit"});
}

TEST_F(ClawLimitsTest, UrdfConfigPosesAndIndicesBeyondTheLimits) {
  Urdf(R"(<geometry><box size="0.1 0.1 0.02"/></geometry>)");
  ExpectLoadError(Write("c1.json", R"({"urdf": "claw.urdf", "T_G_root": {"rpy": [0, 0, 1e300]}})"),
                  {"T_G_root.rpy[2]: 1e+300 rad is beyond"});
  ExpectLoadError(
      Write("c2.json", R"({"urdf": "claw.urdf", "joints": {"slide": {"joint_index": 4000000000}}})"),
      {"joints.slide.joint_index: expected an integer 0..255"});
  ExpectLoadError(
      Write("c3.json",
            R"({"urdf": "claw.urdf", "joints": {"slide": {"limits": {"lower": 0, "upper": 1e9}}}})"),
      {"joint 'slide': upper limit: 1e+09 m is beyond the 0.5 m limit"});
}

TEST_F(ClawLimitsTest, UrdfWithoutGeometryIsAnErrorSayingWhy) {
  // Xacro saved as .urdf: urdfdom skips the macro and sees one bare link.
  ExpectLoadError(Write("hand.urdf", R"(<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="hand">
  <xacro:macro name="hand" params="prefix">
    <link name="${prefix}hand"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  </xacro:macro>
  <link name="world"/>
</robot>)"),
                  {"no link has <collision> geometry (1 link, 0 triangles): this is xacro, not URDF: "
                   "run xacro first"});
  // Visual geometry only: the config's "geometry": "visual" takes it.
  ExpectLoadError(Write("visual.urdf", R"(<robot name="v">
  <link name="base"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
</robot>)"),
                  {"no link has <collision> geometry", "it has <visual> geometry"});
  Write("visual.json", R"({"urdf": "visual.urdf", "geometry": "visual"})");
  EXPECT_EQ(ClawModel::Load((dir_ / "visual.json").string()).links().size(), 1u);
}

TEST_F(ClawLimitsTest, UrdfWithTooManyLinks) {
  std::string chain;
  for (int i = 1; i <= kMaxClawLinks; ++i) {
    chain += "\n  <link name=\"c" + std::to_string(i) + "\"/><joint name=\"cj" + std::to_string(i) +
             "\" type=\"fixed\"><parent link=\"" +
             (i == 1 ? std::string("finger") : "c" + std::to_string(i - 1)) + "\"/><child link=\"c" +
             std::to_string(i) + "\"/></joint>";
  }
  ExpectLoadError(Urdf(R"(<geometry><box size="0.1 0.1 0.02"/></geometry>)", "0 0 0",
                       "lower=\"0\" upper=\"0.04\"", chain),
                  {"258 links, over the limit of 256 per claw"});
}

}  // namespace
}  // namespace graspfill::claw
