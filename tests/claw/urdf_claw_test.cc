// SPDX-License-Identifier: BSD-3-Clause
// Claws from URDF (issue 8 item 6): the shipped Robotiq 3-Finger URDF config
// against its JSON description, the default opening rule and mimic joints on
// small URDFs written here, and the error paths.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "graspfill/claw/claw_mask.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/claw/urdf_claw.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

const std::string kConfigDir = GRASPFILL_SOURCE_DIR "/config/claws";
const std::string kRobotiq = GRASPFILL_SOURCE_DIR "/../shared/assets/grippers/robotiq_3f";

#define SKIP_WITHOUT(dir)                                    \
  if (!fs::is_directory(dir)) {                              \
    GTEST_SKIP() << "gripper assets not found at " << (dir); \
  }

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

// The pixels ClawMask removes from a wall 3 m away (no dilation).
std::vector<bool> MaskedPixels(const ClawModel& model, double opening, const Eigen::Isometry3d& T_C_G) {
  DepthFrame frame;
  const CameraIntrinsics& K = frame.intrinsics;
  frame.depth_m.assign(static_cast<size_t>(K.width) * K.height, 3.0f);
  ClawMaskConfig config;
  config.dilation_px = 0;
  ClawMask mask(config);
  mask.SetClaw(model.Posed(opening));
  mask.Apply(T_C_G, &frame);
  std::vector<bool> masked(frame.depth_m.size());
  for (size_t i = 0; i < masked.size(); ++i) masked[i] = frame.depth_m[i] == 0.0f;
  return masked;
}

TEST(UrdfClawTest, RobotiqUrdfMasksTheSamePixelsAsItsDescription) {
  SKIP_WITHOUT(kRobotiq);
  const ClawModel json = ClawModel::Load(kConfigDir + "/robotiq_3f.json", kRobotiq);
  const ClawModel urdf = ClawModel::Load(kConfigDir + "/robotiq_3f_urdf.json", kRobotiq);
  EXPECT_EQ(urdf.name(), "robotiq_3f_urdf");
  ASSERT_EQ(urdf.links().size(), json.links().size());
  const std::vector<Eigen::Isometry3d> views = {LookAt({0.45, 0.1, 0.15}, {0, 0, 0.09}, {0, 0, -1}),
                                                LookAt({-0.1, 0.45, 0.25}, {0, 0, 0.09}, {0, 0, -1})};
  for (const double opening : {0.0, 0.3, 0.6, 1.0}) {
    for (size_t v = 0; v < views.size(); ++v) {
      const std::vector<bool> a = MaskedPixels(json, opening, views[v]);
      const std::vector<bool> b = MaskedPixels(urdf, opening, views[v]);
      long both = 0, either = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        both += a[i] && b[i];
        either += a[i] || b[i];
      }
      ASSERT_GT(either, 5000) << "the claw should fill part of the image";
      const double agreement = static_cast<double>(both) / static_cast<double>(either);
      EXPECT_GE(agreement, 0.999) << "opening " << opening << " view " << v << ": " << both << " of "
                                  << either << " pixels";
      std::printf("opening %.1f view %zu: %ld of %ld pixels agree (%.5f)\n", opening, v, both, either,
                  agreement);
    }
  }
  // Joint values address the same joints in both.
  std::vector<double> q(11, 0.0);
  q[0] = 0.15;  // scissor
  q[3] = 1.0;   // finger_1 joint_2
  const TriangleMesh pa = json.Posed(0.2, q);
  const TriangleMesh pb = urdf.Posed(0.2, q);
  Eigen::AlignedBox3f ba, bb;
  for (const auto& p : pa.vertices) ba.extend(p);
  for (const auto& p : pb.vertices) bb.extend(p);
  EXPECT_LT((ba.min() - bb.min()).cwiseAbs().maxCoeff(), 1e-5f);
  EXPECT_LT((ba.max() - bb.max()).cwiseAbs().maxCoeff(), 1e-5f);
}

// Files written per test: small URDFs with box fingers and an OBJ palm.
class UrdfFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("urdf_claw_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_ / "pkg" / "meshes");
    Write("pkg/meshes/palm.obj",
          "v -0.05 -0.05 -0.02\nv 0.05 -0.05 -0.02\nv 0 0.05 -0.02\nv 0 0 0\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  // Palm at the root (a package:// mesh), two prismatic fingers along x,
  // the right one a mimic of the left (multiplier -1). The left finger
  // closes towards its *lower* limit (it sits at +x and moves along -x
  // with positive values... see `axis`).
  std::string ParallelUrdf(const std::string& palm_mesh = "package://pkg/meshes/palm.obj") {
    return Write("parallel.urdf", R"(<?xml version="1.0"?>
<robot name="test_parallel">
  <link name="base"><collision><geometry><mesh filename=")" +
                                      palm_mesh + R"("/></geometry></collision></link>
  <link name="left"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <link name="right"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <joint name="left_joint" type="prismatic">
    <parent link="base"/><child link="left"/><origin xyz="0.01 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="1" velocity="1"/>
  </joint>
  <joint name="right_joint" type="prismatic">
    <parent link="base"/><child link="right"/><origin xyz="-0.01 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.04" upper="0" effort="1" velocity="1"/>
    <mimic joint="left_joint" multiplier="-1" offset="0"/>
  </joint>
</robot>)");
  }
  double FingerX(const ClawModel& model, const std::string& link, double opening,
                 const std::vector<double>& q = {}) {
    const auto poses = model.LinkPoses(opening, q);
    for (size_t i = 0; i < model.links().size(); ++i) {
      if (model.links()[i].name == link) return poses[i].translation().x();
    }
    ADD_FAILURE() << "no link " << link;
    return 0.0;
  }
  void ExpectLoadError(const std::string& path, std::initializer_list<std::string> parts,
                       const std::string& mesh_root = "") {
    try {
      ClawModel::Load(path, mesh_root);
      ADD_FAILURE() << "loaded without an error";
    } catch (const std::runtime_error& e) {
      for (const std::string& part : parts) {
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
            << "'" << part << "' not in: " << e.what();
      }
    }
  }
  fs::path dir_;
};

TEST_F(UrdfFileTest, DefaultOpeningDrivesActuatedJointsAndMimicsFollow) {
  const ClawModel model = ClawModel::Load(ParallelUrdf());
  EXPECT_EQ(model.name(), "test_parallel");
  ASSERT_EQ(model.links().size(), 3u);
  EXPECT_EQ(model.links()[0].name, "base");
  EXPECT_FALSE(model.links()[0].mesh.empty());  // found through package://
  // 0 = open: the left finger at its far limit (0.01 + 0.04), 1 = closed.
  EXPECT_NEAR(FingerX(model, "left", 0.0), 0.05, 1e-9);
  EXPECT_NEAR(FingerX(model, "left", 1.0), 0.01, 1e-9);
  EXPECT_NEAR(FingerX(model, "left", 0.25), 0.04, 1e-9);
  // The mimic joint mirrors it.
  EXPECT_NEAR(FingerX(model, "right", 0.0), -0.05, 1e-9);
  EXPECT_NEAR(FingerX(model, "right", 0.25), -0.04, 1e-9);
  // Joint values: [left_joint] in meters, the mimic follows with its
  // multiplier.
  EXPECT_NEAR(FingerX(model, "left", 0.0, {0.02}), 0.03, 1e-9);
  EXPECT_NEAR(FingerX(model, "right", 0.0, {0.02}), -0.03, 1e-9);
  EXPECT_NE(model.opening_doc().find("left_joint"), std::string::npos);
}

TEST_F(UrdfFileTest, ClosedIsTheLimitTowardsTheAxis) {
  // The same gripper with the left finger's axis flipped: now its lower
  // limit is the open one... as seen from the values, the rule decides.
  std::string text;
  {
    std::ifstream in(ParallelUrdf());
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string from = R"(<origin xyz="0.01 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04")";
  const std::string to = R"(<origin xyz="0.05 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.04" upper="0")";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), to);
  const ClawModel model = ClawModel::Load(Write("flipped.urdf", text));
  EXPECT_NEAR(FingerX(model, "left", 0.0), 0.05, 1e-9);  // upper limit 0: open
  EXPECT_NEAR(FingerX(model, "left", 1.0), 0.01, 1e-9);  // lower limit: closed
}

TEST_F(UrdfFileTest, ConfigMapsJointsAndPlacesTheRoot) {
  ParallelUrdf();
  const std::string config = Write("claw.json", R"({
    "urdf": "parallel.urdf",
    "name": "mapped",
    "T_G_root": {"xyz": [0, 0, 0.02]},
    "joints": {"left_joint": {"open": 0.03, "closed": 0.01, "joint_index": 2}}
  })");
  const ClawModel model = ClawModel::Load(config);
  EXPECT_EQ(model.name(), "mapped");
  EXPECT_NEAR(FingerX(model, "left", 0.0), 0.04, 1e-9);
  EXPECT_NEAR(FingerX(model, "left", 1.0), 0.02, 1e-9);
  EXPECT_NEAR(FingerX(model, "right", 1.0), -0.02, 1e-9);
  EXPECT_NEAR(FingerX(model, "left", 0.0, {9, 9, 0.0}), 0.01, 1e-9);
  EXPECT_NEAR(model.LinkPoses(0.0)[0].translation().z(), 0.02, 1e-12);
  // The bundle (what a session description carries) loads the same claw
  // without the files; its mesh (package://) only under the local mesh
  // root, not the bundle's urdf_dir.
  const std::string bundle = UrdfClawBundle(config);
  fs::remove(dir_ / "parallel.urdf");
  fs::remove(config);
  EXPECT_THROW(LoadUrdfClawText(bundle, "session"), std::runtime_error);
  const ClawModel again = LoadUrdfClawText(bundle, "session", dir_.string());
  EXPECT_NEAR(FingerX(again, "left", 0.5), FingerX(model, "left", 0.5), 1e-12);
}

TEST_F(UrdfFileTest, ErrorsNameTheFileAndTheLinkOrJoint) {
  const std::string urdf = ParallelUrdf("package://pkg/meshes/missing.stl");
  ExpectLoadError(urdf, {urdf, "link 'base'", "missing.stl", "not found"});
  ExpectLoadError(Write("broken.urdf", "<robot name='x'><link name='a'></robot>"),
                  {"broken.urdf", "not a valid URDF"});
  Write("pkg/meshes/bad.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1000000\n");
  const std::string bad = ParallelUrdf("package://pkg/meshes/bad.ply");
  ExpectLoadError(bad, {bad, "link 'base'", "bad.ply", "out of range"});
  ParallelUrdf();
  ExpectLoadError(Write("c1.json", R"({"urdf": "parallel.urdf", "joints": {"nope": {}}})"),
                  {"c1.json", "joints.nope", "no such joint"});
  ExpectLoadError(
      Write("c2.json", R"({"urdf": "parallel.urdf", "joints": {"right_joint": {"open": 0, "closed": 0}}})"),
      {"c2.json", "right_joint", "mimic"});
  ExpectLoadError(Write("c3.json", R"({"urdf": "parallel.urdf", "joinst": {}})"),
                  {"c3.json", "unknown key 'joinst'"});
}

TEST(UrdfClawRobotiqTest, DefaultRuleFindsTheHandsClosedEnds) {
  SKIP_WITHOUT(kRobotiq);
  // The xacro's limits but no open/closed ends: the rule must pick the ends
  // robotiq_3f.json took from the hand's documentation (joint_1 and joint_2
  // close towards their upper limits, joint_3 towards its lower one).
  const fs::path dir = fs::path(::testing::TempDir()) / "urdf_claw_robotiq_default";
  fs::create_directories(dir);
  nlohmann::json config = nlohmann::json::parse(std::ifstream(kConfigDir + "/robotiq_3f_urdf.json"));
  config["urdf"] = kRobotiq + "/robotiq-3f-gripper_articulated.urdf";
  for (auto& [name, joint] : config["joints"].items()) {
    joint.erase("open");
    joint.erase("closed");
    joint.erase("joint_index");
  }
  std::ofstream(dir / "c.json") << config.dump();
  const ClawModel by_rule = ClawModel::Load((dir / "c.json").string());
  fs::remove_all(dir);
  const ClawModel json = ClawModel::Load(kConfigDir + "/robotiq_3f.json", kRobotiq);
  int finger_joints = 0;
  for (const Link& a : json.links()) {
    if (a.joint.type == JointType::kFixed || a.name.find("_link_0") != std::string::npos) continue;
    for (const Link& b : by_rule.links()) {
      if (b.name != a.name) continue;
      ++finger_joints;
      EXPECT_NEAR(b.joint.offset, a.joint.offset, 1e-9) << a.name;  // the open end
      EXPECT_NEAR(b.joint.gain, a.joint.gain, 1e-9) << a.name;      // closed - open
    }
  }
  EXPECT_EQ(finger_joints, 9);
}

}  // namespace
}  // namespace graspfill::claw
