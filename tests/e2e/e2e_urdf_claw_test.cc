// SPDX-License-Identifier: BSD-3-Clause
// Claws from URDF through the real CLI (issue 8 item 6): a recording made
// with the Robotiq 3-Finger's URDF claw replays, with the claw its session
// description carries, to a clean cloud; `graspfill claw` writes the posed
// claw; a broken claw file is a clear error (issue 12), not a crash.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "cloud_parts.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill {
namespace {

namespace fs = std::filesystem;
using testing::ObservedPoints;
using testing::RunCli;
using testing::SampleSurface;
using testing::ScratchDir;

const std::string kConfig = GRASPFILL_SOURCE_DIR "/config/claws/robotiq_3f_urdf.json";
const std::string kRobotiq = GRASPFILL_SOURCE_DIR "/../shared/assets/grippers/robotiq_3f";

#define SKIP_WITHOUT_ASSETS()                                   \
  if (!fs::is_directory(kRobotiq)) {                            \
    GTEST_SKIP() << "gripper assets not found at " << kRobotiq; \
  }

TEST(UrdfClawE2E, RecordingWithUrdfClawReplaysClean) {
  SKIP_WITHOUT_ASSETS();
  const std::string dir = ScratchDir("e2e_urdf_claw");
  const auto synth = RunCli("synth --shape cylinder --claw " + kConfig + " --claw-mesh-root " + kRobotiq +
                            " --frames 20 --seed 3 -o " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  // No --claw: the claw comes from the recording's session description,
  // its meshes from the local --claw-mesh-root only (issue 36: a log's
  // recorded root is never read from).
  const auto no_root = RunCli("replay " + dir + "/recording.lcmlog -o " + dir +
                              "/cloud.ply --no-repair --json --lcm-url memq://");
  EXPECT_EQ(no_root.exit_code, 1) << no_root.output;
  const std::string recorded_root = fs::absolute(kRobotiq).lexically_normal().string();
  EXPECT_NE(no_root.output.find("it was made with meshes in " + recorded_root), std::string::npos)
      << no_root.output;
  const auto replay = RunCli("replay " + dir + "/recording.lcmlog -o " + dir +
                             "/cloud.ply --no-repair --json --lcm-url memq:// --claw-mesh-root " + kRobotiq);
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_NE(replay.output.find("robotiq_3f_urdf"), std::string::npos) << replay.output;
  EXPECT_EQ(replay.output.find("warning"), std::string::npos) << replay.output;

  const std::vector<Eigen::Vector3f> fused = ObservedPoints(io::ReadCloudPly(dir + "/cloud.ply"));
  const ObjectCloud gt = io::ReadCloudPly(dir + "/gt_cloud.ply");
  const TriangleMesh claw = io::ReadMesh(dir + "/claw.ply");
  ASSERT_GT(fused.size(), 1000u);
  const std::vector<double> to_gt = mesh::NearestDistances(fused, gt.points_G);
  EXPECT_LT(Percentile(to_gt, 95.0), 0.002);
  // No claw left: < 0.1% of points within 2 mm of the claw and > 2 mm from
  // the object.
  const std::vector<double> to_claw = mesh::NearestDistances(fused, SampleSurface(claw, 0.001f));
  int claw_left = 0;
  for (size_t i = 0; i < fused.size(); ++i) claw_left += to_claw[i] < 0.002 && to_gt[i] > 0.002;
  EXPECT_LT(claw_left, 0.001 * fused.size()) << claw_left << " claw points of " << fused.size();
  // The claw holds the object: some of it within 2 mm of the object.
  const std::vector<double> claw_to_gt = mesh::NearestDistances(SampleSurface(claw, 0.002f), gt.points_G);
  EXPECT_LT(*std::min_element(claw_to_gt.begin(), claw_to_gt.end()), 0.002);
  std::printf("URDF claw e2e: %zu points, p95 %.2f mm, %d claw points\n", fused.size(),
              1e3 * Percentile(to_gt, 95.0), claw_left);
}

TEST(UrdfClawE2E, ClawCommandWritesThePosedClaw) {
  SKIP_WITHOUT_ASSETS();
  const std::string dir = ScratchDir("e2e_claw_command");
  const std::string out = dir + "/claw.ply";
  const auto run = RunCli("claw " + kConfig + " --claw-mesh-root " + kRobotiq + " --opening 0.5 -o " + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const TriangleMesh written = io::ReadMesh(out);
  const TriangleMesh expected = claw::ClawModel::Load(kConfig, kRobotiq).Posed(0.5);
  ASSERT_EQ(written.triangles.size(), expected.triangles.size());
  Eigen::AlignedBox3f a, b;
  for (const auto& v : written.vertices) a.extend(v);
  for (const auto& v : expected.vertices) b.extend(v);
  EXPECT_LT((a.min() - b.min()).cwiseAbs().maxCoeff(), 1e-6f);
  EXPECT_LT((a.max() - b.max()).cwiseAbs().maxCoeff(), 1e-6f);
  // Not overwritten without --force.
  const auto again = RunCli("claw " + kConfig + " --claw-mesh-root " + kRobotiq + " -o " + out);
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;
}

// The installed descriptions are found by name (share/graspfill/claws, as
// the build tree has it), with or without .json, and give the claw their
// file gives; an unknown name lists the built-ins and the installed names.
TEST(UrdfClawE2E, InstalledDescriptionsAreFoundByName) {
  SKIP_WITHOUT_ASSETS();
  const std::string dir = ScratchDir("e2e_claw_by_name");
  const TriangleMesh expected = claw::ClawModel::Load(kConfig, kRobotiq).Posed(0.5);
  for (const std::string name : {"robotiq_3f_urdf", "robotiq_3f_urdf.json"}) {
    const std::string out = dir + "/" + name + ".ply";
    const auto run = RunCli("claw " + name + " --claw-mesh-root " + kRobotiq + " --opening 0.5 -o " + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(io::ReadMesh(out).triangles.size(), expected.triangles.size()) << name;
  }
  const auto unknown = RunCli("claw robotiq3f -o " + dir + "/x.ply");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  for (const char* listed : {"three-finger and parallel", "franka_hand robotiq_3f robotiq_3f_urdf"}) {
    EXPECT_NE(unknown.output.find(listed), std::string::npos) << unknown.output;
  }
  EXPECT_FALSE(fs::exists(dir + "/x.ply"));
}

TEST(UrdfClawE2E, BrokenClawFileIsAnErrorNamingIt) {
  const std::string dir = ScratchDir("e2e_claw_broken");
  std::ofstream(dir + "/bad.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                     "property float y\nproperty float z\nelement face 1\n"
                                     "property list uchar int vertex_indices\nend_header\n"
                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 1000000\n";
  std::ofstream(dir + "/claw.json") << R"({"links": [{"name": "palm", "mesh": "bad.ply"}]})";
  for (const std::string& command :
       {"claw " + dir + "/claw.json -o " + dir + "/out.ply",
        "synth --shape cylinder --frames 2 --claw " + dir + "/claw.json -o " + dir + "/rec"}) {
    const auto run = RunCli(command);
    EXPECT_EQ(run.exit_code, 1) << command << "\n" << run.output;
    EXPECT_NE(run.output.find("claw.json"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("(palm)"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("out of range"), std::string::npos) << run.output;
  }
}

// Issue 36, through `graspfill claw`: a FIFO as the URDF or description
// blocked forever (run under `timeout`, so that a regression fails rather
// than hangs); xacro saved as .urdf gave a claw of 1 link and 0 triangles,
// exit 0; rpy 1e300, a 1e6 m box, a mesh scale of 1e30, an origin of 1e30
// and a prismatic travel of 1e12 m loaded (or ended in "cannot create
// std::vector larger than max_size()" later). Each is now exit 1 naming
// the value and the limit in words.
TEST(UrdfClawE2E, FifosXacroAndClawsBeyondTheLimitsAreErrorsInWords) {
  const std::string dir = ScratchDir("e2e_claw_limits");
  const auto claw = [&](const std::string& spec) {
    return testing::RunShell("LCM_DEFAULT_URL=memq:// timeout 20 " GRASPFILL_CLI " claw " + spec + " -o " +
                             dir + "/out.ply --force 2>&1");
  };
  for (const char* name : {"fifo.urdf", "fifo.json"}) {
    const std::string fifo = dir + "/" + name;
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto r = claw(fifo);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("'" + fifo + "': not a regular file"), std::string::npos) << r.output;
  }
  std::ofstream(dir + "/xacro.urdf") << R"(<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="hand">
  <xacro:macro name="hand" params="prefix">
    <link name="${prefix}hand"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  </xacro:macro>
  <link name="hand_root"/>
</robot>)";
  const auto xacro = claw(dir + "/xacro.urdf");
  EXPECT_EQ(xacro.exit_code, 1) << xacro.output;
  EXPECT_NE(xacro.output.find("this is xacro, not URDF: run xacro first"), std::string::npos) << xacro.output;

  const auto urdf = [&](const std::string& name, const std::string& base, const std::string& joint) {
    std::ofstream(dir + "/" + name) << R"(<robot name="t">
  <link name="base"><collision>)" + base + R"(</collision></link>
  <link name="finger"><collision><geometry><box size="0.01 0.02 0.06"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="finger"/>)" +
                                           joint + R"(
    <axis xyz="1 0 0"/></joint>
</robot>)";
    return dir + "/" + name;
  };
  const std::string limit = R"(<limit lower="0" upper="0.04" effort="1" velocity="1"/>)";
  const std::string box = R"(<geometry><box size="0.1 0.1 0.02"/></geometry>)";
  std::ofstream(dir + "/tet.obj") << "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  std::ofstream(dir + "/rpy.json") << R"({"T_G_root": {"rpy": [1e300, 0, 0]},
      "links": [{"name": "palm", "mesh": "tet.obj"}]})";
  std::ofstream(dir + "/origin.json") << R"({"links": [{"name": "palm", "mesh": "tet.obj"},
      {"name": "finger", "parent": "palm", "mesh": "tet.obj",
       "joint": {"type": "fixed", "origin": {"xyz": [1e30, 0, 0]}}}]})";
  struct Case {
    std::string spec;
    std::string message;
  };
  const std::vector<Case> cases = {
      {urdf("ok.urdf", box, limit), ""},
      {dir + "/rpy.json", "T_G_root.rpy[0]: 1e+300 rad is beyond the 12.5664 rad (4 pi) limit"},
      {urdf("box.urdf", R"(<geometry><box size="1e6 0.1 0.1"/></geometry>)", limit),
       "link 'base': collision box size[0]: 1e+06 m is beyond the 0.5 m limit"},
      {urdf("scale.urdf", R"(<geometry><mesh filename="tet.obj" scale="1e30 1e30 1e30"/></geometry>)", limit),
       "link 'base': collision mesh: scale 1e+30 is beyond the limit of 1000"},
      {dir + "/origin.json", "links[1] (finger).joint.origin.xyz[0]: 1e+30 m is beyond the 0.5 m limit"},
      {urdf("travel.urdf", box, R"(<limit lower="0" upper="1e12" effort="1" velocity="1"/>)"),
       "joint 'slide': upper limit: 1e+12 m is beyond the 0.5 m limit"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.spec);
    const auto r = claw(c.spec);
    if (c.message.empty()) {
      EXPECT_EQ(r.exit_code, 0) << r.output;
      continue;
    }
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("graspfill claw: error: " + c.spec + ": " + c.message), std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("max_size"), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace graspfill
