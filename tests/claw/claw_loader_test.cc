// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "graspfill/claw/claw_mask.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/core/raycaster.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

const std::string kConfigDir = GRASPFILL_SOURCE_DIR "/config/claws";
// The real grippers' meshes are test assets, not part of the product.
const std::string kAssets = GRASPFILL_SOURCE_DIR "/../shared/assets/grippers";
const std::string kRobotiqMeshes = kAssets + "/robotiq_3f";
const std::string kFrankaMeshes = kAssets + "/franka_hand";

#define SKIP_WITHOUT(dir)                                    \
  if (!fs::is_directory(dir)) {                              \
    GTEST_SKIP() << "gripper assets not found at " << (dir); \
  }

Eigen::AlignedBox3f Bounds(const TriangleMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v);
  return box;
}

TriangleMesh PosedLink(const ClawModel& model, const std::string& name, double opening,
                       const std::vector<double>& joints = {}) {
  const auto poses = model.LinkPoses(opening, joints);
  for (size_t i = 0; i < model.links().size(); ++i) {
    if (model.links()[i].name == name) {
      return model.links()[i].mesh.Transformed(poses[i] * model.links()[i].T_link_mesh);
    }
  }
  ADD_FAILURE() << "no link " << name;
  return {};
}

// Camera at `eye_G` looking at `target_G` (optical frame: z forward, y down
// roughly along -G z... any up vector not parallel to the view works).
Eigen::Isometry3d LookAt(const Eigen::Vector3d& eye_G, const Eigen::Vector3d& target_G,
                         const Eigen::Vector3d& up_G) {
  const Eigen::Vector3d z = (target_G - eye_G).normalized();
  const Eigen::Vector3d x = z.cross(up_G).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T_G_C = Eigen::Isometry3d::Identity();
  T_G_C.linear().col(0) = x;
  T_G_C.linear().col(1) = y;
  T_G_C.linear().col(2) = z;
  T_G_C.translation() = eye_G;
  return T_G_C.inverse();
}

// Pixels where a brute-force ray per pixel (mesh posed in C) hits the claw,
// compared with the pixels ClawMask removes from a wall behind the claw.
void ExpectMaskMatchesMesh(const TriangleMesh& claw_G, const Eigen::Isometry3d& T_C_G) {
  DepthFrame frame;
  const CameraIntrinsics& K = frame.intrinsics;
  frame.depth_m.assign(static_cast<size_t>(K.width) * K.height, 3.0f);
  Raycaster reference;
  reference.AddMesh(claw_G.Transformed(T_C_G));
  reference.Commit();
  ClawMaskConfig config;
  config.dilation_px = 0;
  ClawMask mask(config);
  mask.SetClaw(claw_G);
  const int removed = mask.Apply(T_C_G, &frame);
  int hits = 0;
  int missed = 0;
  int extra = 0;
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3f dir((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const bool hit = reference.Cast(Eigen::Vector3f::Zero(), dir.normalized()).hit();
      const bool cut = frame.at(u, v) == 0.0f;
      hits += hit;
      missed += hit && !cut;
      extra += cut && !hit;
    }
  }
  EXPECT_GT(hits, 3000);
  // Only rays grazing an edge may differ (rays in G vs. rays in C).
  EXPECT_LE(missed, 3) << "claw pixels kept";
  EXPECT_LE(extra, 3) << "non-claw pixels removed";
  EXPECT_NEAR(removed, hits, 6);
}

TEST(ClawLoaderTest, RobotiqAssembledBoxMatchesRigidModel) {
  SKIP_WITHOUT(kRobotiqMeshes);
  const ClawModel model = ClawModel::Load(kConfigDir + "/robotiq_3f.json", kRobotiqMeshes);
  EXPECT_EQ(model.name(), "robotiq_3f");
  EXPECT_EQ(model.links().size(), 13u);
  EXPECT_FALSE(model.opening_doc().empty());
  // Open limits: the assets README's 0.213 x 0.220 x 0.130 m box (palm
  // frame x, y, z), here in G: palm y is the approach (G z), palm z is -G y.
  constexpr float kBoxTolM = 0.003f;
  const Eigen::Vector3f size = Bounds(model.Posed(0.0)).sizes();
  EXPECT_NEAR(size.x(), 0.213f, kBoxTolM);
  EXPECT_NEAR(size.y(), 0.130f, kBoxTolM);
  EXPECT_NEAR(size.z(), 0.220f, kBoxTolM);
  // Palm face at z = 0, fingers along +z.
  const Eigen::AlignedBox3f palm = Bounds(PosedLink(model, "palm", 0.0));
  EXPECT_NEAR(palm.max().z(), 0.0f, 1e-4f);
  EXPECT_GT(Bounds(model.Posed(0.0)).max().z(), 0.1f);
  // The middle finger lies along +x, the other two along -x.
  EXPECT_GT(Bounds(PosedLink(model, "finger_middle_link_3", 0.0)).min().x(), 0.05f);
  EXPECT_LT(Bounds(PosedLink(model, "finger_1_link_3", 0.0)).max().x(), -0.05f);
  // Closing pulls the fingertips in.
  EXPECT_LT(Bounds(model.Posed(1.0)).sizes().x(), size.x() - 0.03f);
}

TEST(ClawLoaderTest, RobotiqJointValuesOverrideOpening) {
  SKIP_WITHOUT(kRobotiqMeshes);
  const ClawModel model = ClawModel::Load(kConfigDir + "/robotiq_3f.json", kRobotiqMeshes);
  // Explicit open-limit joint values reproduce opening 0.
  const std::vector<double> open = {0, 0, 0.0495, 0, -0.0523, 0.0495, 0, -0.0523, 0.0495, 0, -0.0523};
  const auto a = model.LinkPoses(0.0);
  const auto b = model.LinkPoses(0.7, open);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].isApprox(b[i], 1e-9)) << model.links()[i].name;
  }
  // A scissor value turns finger 1 only.
  std::vector<double> scissor = open;
  scissor[0] = 0.15;
  const auto c = model.LinkPoses(0.0, scissor);
  EXPECT_FALSE(a[1].isApprox(c[1], 1e-6));
  EXPECT_TRUE(a[5].isApprox(c[5], 1e-9));
}

TEST(ClawLoaderTest, FrankaFingerGapEqualsOpening) {
  SKIP_WITHOUT(kFrankaMeshes);
  const ClawModel model = ClawModel::Load(kConfigDir + "/franka_hand.json", kFrankaMeshes);
  EXPECT_EQ(model.links().size(), 3u);
  const auto gap = [&](double opening, const std::vector<double>& joints) {
    return Bounds(PosedLink(model, "panda_leftfinger", opening, joints)).min().x() -
           Bounds(PosedLink(model, "panda_rightfinger", opening, joints)).max().x();
  };
  for (double opening : {0.0, 0.01, 0.035, 0.08}) {
    EXPECT_NEAR(gap(opening, {}), opening, 1e-5) << opening;
  }
  EXPECT_NEAR(gap(0.2, {}), 0.08, 1e-5);       // clamped to the limits
  EXPECT_NEAR(gap(0.0, {0.015}), 0.03, 1e-5);  // joint value = half gap
  // Palm face (hand top) at z = 0; fingers centred on G's axis.
  EXPECT_NEAR(Bounds(PosedLink(model, "panda_hand", 0.0)).max().z(), 0.0f, 1e-4f);
  const Eigen::AlignedBox3f fingers = Bounds(model.Posed(0.04));
  EXPECT_GT(fingers.max().z(), 0.04f);
}

TEST(ClawLoaderTest, RobotiqMaskMatchesMeshes) {
  SKIP_WITHOUT(kRobotiqMeshes);
  const ClawModel model = ClawModel::Load(kConfigDir + "/robotiq_3f.json", kRobotiqMeshes);
  const TriangleMesh claw_G = model.Posed(0.3);
  ExpectMaskMatchesMesh(claw_G, LookAt(Eigen::Vector3d(0.35, -0.25, 0.25), Eigen::Vector3d(0, 0, 0.06),
                                       Eigen::Vector3d(0, 0, 1)));
  ExpectMaskMatchesMesh(
      claw_G, LookAt(Eigen::Vector3d(0.05, 0.6, 0.1), Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d(1, 0, 0)));
}

TEST(ClawLoaderTest, FrankaMaskMatchesMeshes) {
  SKIP_WITHOUT(kFrankaMeshes);
  const ClawModel model = ClawModel::Load(kConfigDir + "/franka_hand.json", kFrankaMeshes);
  ExpectMaskMatchesMesh(model.Posed(0.05), LookAt(Eigen::Vector3d(0.1, -0.3, 0.2), Eigen::Vector3d(0, 0, 0.0),
                                                  Eigen::Vector3d(0, 0, 1)));
}

// Error paths and the format's conventions, on small files written here.
class ClawLoaderFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("claw_loader_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
    // A right tetrahedron of 0.1 m legs, outward-facing (within the claw
    // limits' reach).
    Write("tet.obj",
          "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    Write("empty.ply",
          "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
          "property float y\nproperty float z\nelement face 0\n"
          "property list uchar int vertex_indices\nend_header\n"
          "0 0 0\n1 0 0\n0 1 0\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  // A description with `links` as the links array.
  std::string Description(const std::string& links) {
    return Write("claw.json", R"({"name": "test", "links": )" + links + "}");
  }
  void ExpectError(const std::string& path, const std::string& expected) {
    try {
      ClawModel::Load(path);
      ADD_FAILURE() << "no error, expected: " << expected;
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(expected), std::string::npos) << message;
      EXPECT_NE(message.find(path), std::string::npos) << message;
    }
  }

  fs::path dir_;
};

TEST_F(ClawLoaderFileTest, MissingFile) {
  ExpectError((dir_ / "nope.json").string(), "cannot open claw description file");
}

TEST_F(ClawLoaderFileTest, BadJson) {
  ExpectError(Write("bad.json", "{\"links\": [ {\"name\": }"), "bad JSON");
}

TEST_F(ClawLoaderFileTest, UnknownParent) {
  ExpectError(Description(R"([{"name": "a"}, {"name": "b", "parent": "nope"}])"),
              "links[1] (b).parent: unknown parent link 'nope'");
}

TEST_F(ClawLoaderFileTest, MissingMesh) {
  ExpectError(Description(R"([{"name": "a", "mesh": "missing.stl"}])"),
              "links[0] (a).mesh: mesh file not found");
}

TEST_F(ClawLoaderFileTest, EmptyMesh) {
  ExpectError(Description(R"([{"name": "a", "mesh": "empty.ply"}])"),
              "links[0] (a).mesh: cannot read mesh file");
}

TEST_F(ClawLoaderFileTest, BadJointType) {
  ExpectError(Description(R"([{"name": "a"}, {"name": "b", "parent": "a",
                      "joint": {"type": "spherical"}}])"),
              "links[1] (b).joint.type: unknown joint type 'spherical'");
}

TEST_F(ClawLoaderFileTest, MisspeltKeyAndMissingDrive) {
  ExpectError(Description(R"([{"name": "a", "mesh_orgin": {}}])"), "links[0] (a): unknown key 'mesh_orgin'");
  ExpectError(Description(R"([{"name": "a", "joint": {"type": "revolute",
                      "axis": [0, 0, 1],
                      "limits": {"lower": 0, "upper": 1}}}])"),
              "links[0] (a).joint.drive: missing");
  ExpectError(Description(R"([{"name": "a", "joint": {"type": "prismatic",
                      "axis": [0, 0], "limits": {"lower": 0, "upper": 1},
                      "drive": {"joint_index": 0}}}])"),
              "links[0] (a).joint.axis: expected an array of 3 numbers");
}

TEST_F(ClawLoaderFileTest, KinematicsConventions) {
  // Child listed before its parent; mesh path relative to the file; URDF
  // rpy; a revolute joint driven by the opening; mesh_scale.
  const std::string path = Write("claw.json", R"({
    "name": "toy",
    "opening_doc": "radians",
    "T_G_root": {"xyz": [0, 0, -0.1]},
    "links": [
      {"name": "arm", "parent": "base", "mesh": "tet.obj", "mesh_scale": 0.5,
       "mesh_origin": {"xyz": [0.05, 0, 0]},
       "joint": {"type": "revolute", "origin": {"xyz": [0, 0, 0.15],
                 "rpy": [0.1, 0.2, 0.3]}, "axis": [0, 0, 2],
                 "limits": {"lower": -1, "upper": 1},
                 "drive": {"opening_gain": 2.0, "opening_offset": 0.1}}},
      {"name": "base", "mesh": "tet.obj"}
    ]})");
  const ClawModel model = ClawModel::Load(path);
  ASSERT_EQ(model.links().size(), 2u);
  EXPECT_EQ(model.links()[0].name, "base");
  EXPECT_EQ(model.links()[1].parent, 0);
  EXPECT_EQ(model.opening_doc(), "radians");
  const double opening = 0.2;
  const double q = 0.1 + 2.0 * opening;
  Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
  expected.translation() = Eigen::Vector3d(0, 0, 0.05);
  expected.linear() =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const auto poses = model.LinkPoses(opening);
  EXPECT_TRUE(poses[1].isApprox(expected, 1e-12));
  EXPECT_NEAR(poses[0].translation().z(), -0.1, 1e-12);
  // Scaled mesh: the tetrahedron's far vertex at 0.05 m.
  EXPECT_NEAR(Bounds(model.links()[1].mesh).max().x(), 0.05f, 1e-6f);
  // Clamped: opening 10 gives q = upper = 1.
  EXPECT_TRUE(model.LinkPoses(10.0)[1].linear().isApprox(
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix(),
      1e-12));
  // mesh_root overrides the file's folder.
  fs::create_directories(dir_ / "meshes");
  fs::copy_file(dir_ / "tet.obj", dir_ / "meshes" / "tet.obj");
  fs::remove(dir_ / "tet.obj");
  EXPECT_THROW(ClawModel::Load(path), std::runtime_error);
  EXPECT_EQ(ClawModel::Load(path, (dir_ / "meshes").string()).links().size(), 2u);
}

}  // namespace
}  // namespace graspfill::claw
