// SPDX-License-Identifier: BSD-3-Clause
// Claw text from a session description (the bus, a log) reads meshes only
// under the local mesh root (issue 36): no absolute path, no '..', no
// package:// or file:// way out, no folder the text itself names.
#include "graspfill/claw/mesh_path.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/claw/urdf_claw.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ConfinedMeshPath, StaysUnderTheRoot) {
  EXPECT_EQ(ConfinedMeshPath("/meshes", "a/b.stl"), fs::path("/meshes/a/b.stl"));
  EXPECT_EQ(ConfinedMeshPath("rel", "x..y.stl"), fs::path("rel/x..y.stl"));
  for (const char* bad : {"/etc/passwd", "../x.stl", "a/../../x.stl", "a/..", ""}) {
    EXPECT_NE(ErrorOf([&] { ConfinedMeshPath("/meshes", bad); }), "") << bad;
  }
  EXPECT_NE(ErrorOf([] { ConfinedMeshPath("", "a.stl"); }).find("none was given"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ConfinedMeshPath("/m", "/abs.stl"); }).find("absolute"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ConfinedMeshPath("/m", "../a.stl"); }).find("'..'"), std::string::npos);
}

// A root with a mesh in it, and the same mesh beside the root (outside it).
class SessionClawText : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("mesh_path_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "root" / "pkg");
    for (const fs::path& p : {dir_ / "root" / "pkg" / "palm.obj", dir_ / "outside.obj"}) {
      std::ofstream(p) << "v -0.05 -0.05 -0.02\nv 0.05 -0.05 -0.02\nv 0 0.05 -0.02\nv 0 0 0\n"
                          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    }
    root_ = (dir_ / "root").string();
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Description(const std::string& mesh) const {
    return R"({"links": [{"name": "palm", "mesh": ")" + mesh + R"("}]})";
  }
  std::string Urdf(const std::string& filename) const {
    return R"(<robot name="r"><link name="palm"><collision><geometry><mesh filename=")" + filename +
           R"("/></geometry></collision></link></robot>)";
  }
  fs::path dir_;
  std::string root_;
};

TEST_F(SessionClawText, DescriptionMeshesOnlyUnderTheLocalRoot) {
  const ClawModel model =
      ClawModel::LoadDescriptionText(Description("pkg/palm.obj"), "given", "claw description 'given'", root_);
  EXPECT_EQ(model.name(), "given");
  ASSERT_EQ(model.links().size(), 1u);
  EXPECT_EQ(model.links()[0].mesh.triangles.size(), 4u);
  const std::string outside = (dir_ / "outside.obj").string();
  for (const std::string& ref :
       {outside, std::string("../outside.obj"), std::string("pkg/../../outside.obj")}) {
    const std::string error = ErrorOf(
        [&] { ClawModel::LoadDescriptionText(Description(ref), "x", "claw description 'x'", root_); });
    EXPECT_NE(error.find("claw description 'x': links[0] (palm).mesh: mesh '" + ref + "'"), std::string::npos)
        << error;
  }
  // No local root: no mesh at all, even one the text names absolutely.
  EXPECT_NE(ErrorOf([&] {
              ClawModel::LoadDescriptionText(Description(outside), "x", "x", "");
            }).find("none was given"),
            std::string::npos);
  // A local file still reads its own meshes as before (relative to it).
  std::ofstream(dir_ / "root" / "claw.json") << Description("pkg/palm.obj");
  EXPECT_EQ(ClawModel::Load((dir_ / "root" / "claw.json").string()).links().size(), 1u);
}

TEST_F(SessionClawText, UrdfMeshesOnlyUnderTheLocalRoot) {
  EXPECT_EQ(LoadUrdfClawText(Urdf("package://pkg/palm.obj"), "u", root_).links().size(), 1u);
  EXPECT_EQ(LoadUrdfClawText(Urdf("pkg/palm.obj"), "u", root_).links().size(), 1u);
  const std::string outside = (dir_ / "outside.obj").string();
  for (const std::string& uri :
       {"file://" + outside, outside, std::string("../outside.obj"),
        std::string("package://pkg/../../outside.obj"), std::string("package:///") + outside}) {
    const std::string error = ErrorOf([&] { LoadUrdfClawText(Urdf(uri), "u", root_); });
    EXPECT_NE(error.find("u: link 'palm': mesh '"), std::string::npos) << uri << ": " << error;
  }
  // The text's own folder (a bundle's urdf_dir) is not a root.
  const std::string bundle = nlohmann::json{{"urdf_text", Urdf("pkg/palm.obj")}, {"urdf_dir", root_}}.dump();
  EXPECT_NE(ErrorOf([&] { LoadUrdfClawText(bundle, "u", ""); }).find("none was given"), std::string::npos);
  EXPECT_EQ(LoadUrdfClawText(bundle, "u", root_).links().size(), 1u);
  // Primitives need no root.
  EXPECT_EQ(LoadUrdfClawText(R"(<robot name="r"><link name="palm"><collision><geometry>)"
                             R"(<box size="0.1 0.1 0.02"/></geometry></collision></link></robot>)",
                             "u", "")
                .links()
                .size(),
            1u);
}

}  // namespace
}  // namespace graspfill::claw
