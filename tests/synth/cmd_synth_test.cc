// SPDX-License-Identifier: BSD-3-Clause
// `graspfill synth` end to end: arguments, the files it writes, and the
// recording read back with LCM's own log reader and graspfill's decoders;
// and `--protocol paper`, its clouds checked against the exact shape.
#include <gtest/gtest.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/object_slip.hpp"
#include "synth/scene.hpp"
#include "synth/shapes.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;

class SynthCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("graspfill_synth_cli_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

TEST_F(SynthCliTest, UsageErrorsExitTwo) {
  EXPECT_EQ(RunSynth({"--help"}), 0);
  EXPECT_EQ(RunSynth({}), 2);
  const std::string out = dir_.string();
  EXPECT_EQ(RunSynth({"--shape", "cube", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid"}), 2);  // no -o
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--mesh", "a.ply", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--size", "7x7x14", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--size", "0.07x0.07", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--frames", "0", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--seed", "-3", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--grasp", "bottom", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--claw", "robotiq", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--frobnicate", "-o", out}), 2);
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(SynthCliTest, UnreadableMeshExitsOne) {
  EXPECT_EQ(RunSynth({"--mesh", (dir_ / "missing.ply").string(), "-o", dir_.string()}), 1);
}

TEST_F(SynthCliTest, WritesARecordingAndItsGroundTruth) {
  const std::string out = dir_.string();
  ASSERT_EQ(
      RunSynth({"--shape", "cylinder", "--grasp", "top-oblique", "--frames", "4", "--seed", "5", "-o", out}),
      0);
  for (const char* name :
       {"recording.lcmlog", "gt_mesh.ply", "gt_cloud.ply", "claw.ply", "scene.json", "claw/claw.json"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
  }

  // The log: the session description first, then depth and gripper
  // events in time order, stamped with utime.
  const io::ChannelNames channels;
  lcm::LogFile log((dir_ / "recording.lcmlog").string(), "r");
  ASSERT_TRUE(log.good());
  int depth_events = 0, gripper_events = 0, session_events = 0, events = 0;
  int64_t last_timestamp = 0;
  DepthFrame frame;
  GripperState state;
  io::SessionDescription session;
  std::string error;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    EXPECT_GE(event->timestamp, last_timestamp);
    last_timestamp = event->timestamp;
    ++events;
    if (event->channel == channels.session) {
      EXPECT_EQ(events, 1) << "the session description is not at the head of the log";
      ASSERT_TRUE(io::DecodeSessionDescription(event->data, event->datalen, &session, &error)) << error;
      EXPECT_EQ(session.utime, event->timestamp);
      ++session_events;
    } else if (event->channel == channels.depth) {
      ASSERT_TRUE(io::DecodeDepthImage(event->data, event->datalen, &frame, &error)) << error;
      EXPECT_EQ(frame.utime, event->timestamp);
      EXPECT_EQ(frame.intrinsics, CameraIntrinsics{});
      int valid = 0;
      for (float z : frame.depth_m) valid += z > 0.0f;
      EXPECT_GT(valid, 0.9 * frame.depth_m.size());
      ++depth_events;
    } else if (event->channel == channels.gripper_state) {
      ASSERT_TRUE(
          io::DecodeGripperState(event->data, event->datalen, Eigen::Isometry3d::Identity(), &state, &error))
          << error;
      EXPECT_EQ(state.utime, event->timestamp);
      EXPECT_GT(state.opening_m, 0.03);
      ++gripper_events;
    } else {
      ADD_FAILURE() << "unexpected channel " << event->channel;
    }
  }
  EXPECT_EQ(session_events, 1);
  EXPECT_EQ(depth_events, 4);
  // 4 frames span 0.1 s, plus 0.1 s of states either side at 100 Hz.
  EXPECT_GE(gripper_events, 29);

  // scene.json says what was made.
  std::ifstream in(dir_ / "scene.json");
  const nlohmann::json scene = nlohmann::json::parse(in);
  EXPECT_EQ(scene["object"]["shape"], "cylinder");
  EXPECT_EQ(scene["grasp"], "top-oblique");
  EXPECT_EQ(scene["seed"], 5);
  EXPECT_EQ(scene["num_frames"], 4);
  EXPECT_EQ(scene["log"]["depth_channel"], channels.depth);
  EXPECT_EQ(scene["log"]["bytes"], fs::file_size(dir_ / "recording.lcmlog"));
  const Eigen::Vector3d ws_min(scene["workspace_box_G"]["min"][0], scene["workspace_box_G"]["min"][1],
                               scene["workspace_box_G"]["min"][2]);
  const Eigen::Vector3d ws_max(scene["workspace_box_G"]["max"][0], scene["workspace_box_G"]["max"][1],
                               scene["workspace_box_G"]["max"][2]);

  // Ground truth in G: inside the workspace box, the cloud on the mesh.
  const TriangleMesh gt_mesh = io::ReadMesh((dir_ / "gt_mesh.ply").string());
  const Eigen::AlignedBox3d mesh_box = mesh::Bounds(gt_mesh);
  EXPECT_TRUE(Eigen::AlignedBox3d(ws_min, ws_max).contains(mesh_box));
  const ObjectCloud gt_cloud = io::ReadCloudPly((dir_ / "gt_cloud.ply").string());
  EXPECT_EQ(gt_cloud.size(), static_cast<size_t>(synth::kDefaultGroundTruthPoints));
  EXPECT_EQ(gt_cloud.normals_G.size(), gt_cloud.size());
  Eigen::AlignedBox3d grown = mesh_box;
  grown.min().array() -= 1e-6;
  grown.max().array() += 1e-6;
  for (size_t i = 0; i < gt_cloud.size(); i += 997) {
    EXPECT_TRUE(grown.contains(gt_cloud.points_G[i].cast<double>()));
  }

  // The claw description reproduces claw.ply at the recorded opening.
  const claw::ClawModel model = claw::ClawModel::Load((dir_ / "claw" / "claw.json").string());
  const TriangleMesh posed = model.Posed(state.opening_m);
  const TriangleMesh claw_ply = io::ReadMesh((dir_ / "claw.ply").string());
  EXPECT_TRUE(mesh::Bounds(posed).isApprox(mesh::Bounds(claw_ply), 1e-5));
  EXPECT_NEAR(mesh::SurfaceArea(posed), mesh::SurfaceArea(claw_ply), 1e-6);

  // The session description: the claw as rendered (scene.json's claw.used),
  // nothing else asked of the receiver.
  EXPECT_EQ(session.software_version, io::SoftwareVersion());
  EXPECT_EQ(session.claw_kind, io::SessionClawKind::kBuiltin);
  EXPECT_EQ(session.claw_name, "three-finger");
  EXPECT_EQ(nlohmann::json::parse(session.claw_text), scene["claw"]["used"]);
  EXPECT_TRUE(session.T_C_B.matrix().isIdentity(0.0));
  EXPECT_FALSE(session.intrinsics.has_value());
  EXPECT_FALSE(session.workspace_G.has_value());
  EXPECT_EQ(session.voxel_m, 0.0);
}

// The 10x10x20 cm cuboid held in the middle needs longer fingers than the
// built-in parallel claw's: the session description carries them.
TEST_F(SynthCliTest, SessionDescriptionCarriesTheClawAsUsed) {
  const std::string out = dir_.string();
  ASSERT_EQ(RunSynth({"--shape", "cuboid", "--size", "0.10x0.10x0.20", "--claw", "parallel", "--grasp",
                      "middle-straight", "--frames", "1", "--wall-m", "0", "-o", out}),
            0);
  std::ifstream in(dir_ / "scene.json");
  const nlohmann::json scene = nlohmann::json::parse(in);
  ASSERT_NE(scene["claw"]["used"], scene["claw"]["config"]);  // the premise
  lcm::LogFile log((dir_ / "recording.lcmlog").string(), "r");
  const lcm::LogEvent* event = log.readNextEvent();
  ASSERT_NE(event, nullptr);
  ASSERT_EQ(event->channel, io::ChannelNames{}.session);
  io::SessionDescription session;
  std::string error;
  ASSERT_TRUE(io::DecodeSessionDescription(event->data, event->datalen, &session, &error)) << error;
  EXPECT_EQ(session.claw_name, "parallel");
  EXPECT_EQ(nlohmann::json::parse(session.claw_text), scene["claw"]["used"]);
}

// The sensor's errors reach the frames, and scene.json holds their truth.
TEST_F(SynthCliTest, SensorErrorsAreRecordedWithTheirTruth) {
  const std::string out = dir_.string();
  ASSERT_EQ(
      RunSynth({"--shape", "sphere", "--frames", "2", "--ideal", "--depth-scale", "1.01",
                "--intrinsics-scale", "1.005", "--wobble-mm", "0.5", "--mixed-pixels", "0.25", "-o", out}),
      0);
  std::ifstream in(dir_ / "scene.json");
  const nlohmann::json sensor = nlohmann::json::parse(in)["sensor"];
  EXPECT_EQ(sensor["depth_scale"], 1.01);
  EXPECT_EQ(sensor["intrinsics_scale"], 1.005);
  EXPECT_EQ(sensor["wobble_m"], 0.0005);
  EXPECT_EQ(sensor["mixed_pixel_prob"], 0.25);
  lcm::LogFile log((dir_ / "recording.lcmlog").string(), "r");
  ASSERT_TRUE(log.good());
  DepthFrame frame;
  std::string error;
  bool decoded = false;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != io::ChannelNames{}.depth) continue;
    ASSERT_TRUE(io::DecodeDepthImage(event->data, event->datalen, &frame, &error)) << error;
    decoded = true;
    break;
  }
  ASSERT_TRUE(decoded);
  EXPECT_NEAR(frame.intrinsics.fx, 1.005 * synth::IntrinsicsAtResolution(640, 480).fx, 1e-9);
  for (const std::vector<std::string>& bad : {std::vector<std::string>{"--depth-scale", "1.5"},
                                              {"--intrinsics-scale", "0"},
                                              {"--wobble-mm", "-1"},
                                              {"--mixed-pixels", "2"}}) {
    Args args = {"--shape", "cuboid", "-o", (dir_ / "bad").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    EXPECT_EQ(RunSynth(args), 2) << bad[0] << " " << bad[1];
  }
}

TEST_F(SynthCliTest, NumbersAreParsedStrictly) {
  const std::string out = dir_.string();
  for (const std::vector<std::string>& bad : {std::vector<std::string>{"--frames", "12x"},
                                              {"--frames", "1e3"},
                                              {"--frames", "0"},
                                              {"--seed", "1.5"},
                                              {"--seed", " 1"},
                                              {"--wall-m", "nan"},
                                              {"--wall-m", "abc"},
                                              {"--wall-m", "-1"},
                                              {"--size", "0.07x0.07x0.14cm"}}) {
    Args args = {"--shape", "cuboid", "-o", out};
    args.insert(args.end(), bad.begin(), bad.end());
    EXPECT_EQ(RunSynth(args), 2) << bad[0] << " " << bad[1];
  }
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(SynthCliTest, RefusesToOverwriteWithoutForce) {
  const std::string out = dir_.string();
  ASSERT_EQ(RunSynth({"--shape", "sphere", "--frames", "1", "-o", out}), 0);
  const auto size = fs::file_size(dir_ / "recording.lcmlog");
  EXPECT_EQ(RunSynth({"--shape", "sphere", "--frames", "2", "-o", out}), 1);
  EXPECT_EQ(fs::file_size(dir_ / "recording.lcmlog"), size);
  EXPECT_EQ(RunSynth({"--shape", "sphere", "--frames", "2", "--force", "-o", out}), 0);
  EXPECT_GT(fs::file_size(dir_ / "recording.lcmlog"), size);
}

TEST_F(SynthCliTest, SynthesizesFromAMeshFile) {
  fs::create_directories(dir_);
  // An egg-like ellipsoid in an arbitrary place: synth moves it into O.
  TriangleMesh mesh = synth::MakeShape(synth::Shape::kEllipsoid, Eigen::Vector3d(0.06, 0.06, 0.1), 48);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.2, 0.1, -0.3);
  const std::string mesh_path = (dir_ / "egg.ply").string();
  io::WriteMeshPly(mesh_path, mesh.Transformed(T));
  const std::string out = (dir_ / "out").string();
  ASSERT_EQ(RunSynth({"--mesh", mesh_path, "--claw", "parallel", "--frames", "2", "-o", out}), 0);
  std::ifstream in(dir_ / "out" / "scene.json");
  const nlohmann::json scene = nlohmann::json::parse(in);
  EXPECT_EQ(scene["object"]["source"], "mesh");
  EXPECT_EQ(scene["claw"]["type"], "parallel");
  EXPECT_NEAR(scene["object"]["size_m"][2].get<double>(), 0.1, 1e-6);

  // A mesh in millimetres is refused rather than rendered 1000x too big.
  const std::string mm_path = (dir_ / "egg_mm.ply").string();
  TriangleMesh mm = mesh;
  for (Eigen::Vector3f& v : mm.vertices) v *= 1000.0f;
  io::WriteMeshPly(mm_path, mm);
  EXPECT_EQ(RunSynth({"--mesh", mm_path, "-o", (dir_ / "mm").string()}), 1);
}

// --mesh-scale and --mesh-up: a mesh in millimetres with +y up (as many
// OBJ and glTF exports are) comes out as the same object in meters, +z up.
TEST_F(SynthCliTest, ScalesAndTurnsAMeshFileUp) {
  fs::create_directories(dir_);
  // An egg 60 x 40 mm across and 100 mm tall, its height along +y, in mm.
  const TriangleMesh egg = synth::MakeShape(synth::Shape::kEllipsoid, Eigen::Vector3d(0.06, 0.04, 0.1), 48);
  const Eigen::Isometry3d z_to_y(Eigen::AngleAxisd(-0.5 * M_PI, Eigen::Vector3d::UnitX()));
  TriangleMesh mm = egg.Transformed(z_to_y);
  for (Eigen::Vector3f& v : mm.vertices) v *= 1000.0f;
  const Eigen::Vector3d file_size = mesh::Bounds(mm).sizes();
  ASSERT_NEAR(file_size.y(), 100.0, 1e-3);  // the height along y, in mm
  const std::string mm_path = (dir_ / "egg_mm_y_up.ply").string();
  io::WriteMeshPly(mm_path, mm);
  const std::string out = (dir_ / "out").string();
  ASSERT_EQ(RunSynth({"--mesh", mm_path, "--mesh-scale", "0.001", "--mesh-up", "y", "--claw", "parallel",
                      "--frames", "2", "-o", out}),
            0);
  const nlohmann::json scene = nlohmann::json::parse(std::ifstream(dir_ / "out" / "scene.json"));
  EXPECT_EQ(scene["object"]["mesh_scale"].get<double>(), 0.001);
  EXPECT_EQ(scene["object"]["mesh_up"], "y");
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(scene["object"]["size_m"][k].get<double>(), mesh::Bounds(egg).sizes()[k], 1e-6) << k;
  }
  // The ground truth is the egg standing up, in meters.
  const Eigen::Vector3d gt_size = mesh::Bounds(io::ReadMesh((dir_ / "out" / "gt_mesh.ply").string())).sizes();
  EXPECT_NEAR(gt_size.z(), 0.1, 1e-4);
  // Bad values, and the options without --mesh, are usage errors.
  EXPECT_EQ(RunSynth({"--mesh", mm_path, "--mesh-scale", "0", "-o", (dir_ / "a").string()}), 2);
  EXPECT_EQ(RunSynth({"--mesh", mm_path, "--mesh-up", "x", "-o", (dir_ / "a").string()}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--mesh-scale", "0.001", "-o", (dir_ / "a").string()}), 2);
  EXPECT_FALSE(fs::exists(dir_ / "a"));
}

// ---- --protocol paper ----

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

Eigen::Isometry3d PoseFromRows(const nlohmann::json& rows) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = rows.at(r).at(c).get<double>();
  }
  return T;
}

// Signed distance to the cuboid of size W x D x H in the object frame
// (x, y centred, base at z = 0): zero on its surface.
double CuboidSignedDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& size) {
  const Eigen::Vector3d centre(0, 0, 0.5 * size.z());
  const Eigen::Vector3d q = (p - centre).cwiseAbs() - 0.5 * size;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

TEST_F(SynthCliTest, ProtocolUsageErrorsExitTwo) {
  const std::string out = dir_.string();
  const Args paper = {"--protocol", "paper", "--shape", "cuboid", "-o", out};
  auto with = [&](std::initializer_list<std::string> extra) {
    Args args = paper;
    args.insert(args.end(), extra);
    return args;
  };
  EXPECT_EQ(RunSynth({"--protocol", "foo", "--shape", "cuboid", "-o", out}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "-o", out, "--protocol"}), 2);  // no value
  // Options of recordings are refused, not silently ignored.
  EXPECT_EQ(RunSynth(with({"--claw", "parallel"})), 2);
  EXPECT_EQ(RunSynth(with({"--frames", "4"})), 2);
  EXPECT_EQ(RunSynth(with({"--ideal"})), 2);
  EXPECT_EQ(RunSynth(with({"--wall-m", "0"})), 2);
  EXPECT_EQ(RunSynth({"--protocol", "paper", "--mesh", "a.ply", "-o", out}), 2);
  // --points: protocol only, 1000..5000000.
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--points", "20000", "-o", out}), 2);
  EXPECT_EQ(RunSynth(with({"--points", "999"})), 2);
  EXPECT_EQ(RunSynth(with({"--points", "5000001"})), 2);
  EXPECT_EQ(RunSynth(with({"--points", "2e4"})), 2);
  EXPECT_EQ(RunSynth(with({"--points", "-5000"})), 2);
  EXPECT_EQ(RunSynth({"--protocol", "paper", "--shape", "cuboid"}), 2);  // no -o
  EXPECT_EQ(RunSynth({"--protocol", "paper", "-o", out}), 2);            // no --shape
  EXPECT_EQ(RunSynth({"--protocol", "paper", "--shape", "cube", "-o", out}), 2);
  EXPECT_EQ(RunSynth(with({"--size", "0.07x0.07"})), 2);
  EXPECT_EQ(RunSynth(with({"--size", "70x70x140"})), 2);
  EXPECT_EQ(RunSynth(with({"--grasp", "bottom"})), 2);
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(SynthCliTest, ProtocolWritesAHoleyCloudOnTheShapeAndItsTruth) {
  const std::string out = dir_.string();
  ASSERT_EQ(
      RunSynth({"--protocol", "paper", "--shape", "cuboid", "--seed", "3", "--points", "20000", "-o", out}),
      0);
  for (const char* name : {"holey.ply", "gt_cloud.ply", "protocol.json"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "recording.lcmlog"));

  const ObjectCloud holey = io::ReadCloudPly((dir_ / "holey.ply").string());
  const ObjectCloud truth = io::ReadCloudPly((dir_ / "gt_cloud.ply").string());
  const nlohmann::json protocol = ReadJson(dir_ / "protocol.json");
  EXPECT_NE(protocol["doc"].get<std::string>().find("Cui et al. 2021, section 3.1"), std::string::npos);
  EXPECT_EQ(protocol["shape"], "cuboid");
  EXPECT_EQ(protocol["grasp"], "top-straight");
  EXPECT_EQ(protocol["seed"], 3);
  EXPECT_EQ(protocol["points"], 20000);
  EXPECT_EQ(protocol["holey"]["points"], holey.size());
  EXPECT_EQ(protocol["ground_truth"]["points"], truth.size());
  const Eigen::Vector3d size(protocol["size_m"][0], protocol["size_m"][1], protocol["size_m"][2]);
  EXPECT_TRUE(size.isApprox(Eigen::Vector3d(0.07, 0.07, 0.14), 1e-12));
  ASSERT_EQ(protocol["claw_hole_centres"].size(), 3u);

  // The repair's input: observed points only, no normals; the truth is the
  // whole surface, so it has more points.
  EXPECT_TRUE(holey.normals_G.empty());
  for (Provenance p : holey.provenance) ASSERT_EQ(p, Provenance::kObserved);
  EXPECT_EQ(truth.size(), 20000u);
  EXPECT_LT(holey.size(), truth.size());
  EXPECT_GT(holey.size(), truth.size() / 2);

  // Both clouds, moved back into the object frame with the recorded pose,
  // lie on the cuboid: the pose is rigid and shared, and holes only remove.
  const Eigen::Isometry3d T_cloud_object = PoseFromRows(protocol["T_cloud_object"]);
  EXPECT_FALSE(T_cloud_object.isApprox(Eigen::Isometry3d::Identity()));  // a random pose
  const Eigen::Isometry3d T_object_cloud = T_cloud_object.inverse();
  auto to_object = [&](const Eigen::Vector3f& p) { return T_object_cloud * p.cast<double>(); };
  // Inside the top face, away from its rim (where the walls end).
  auto on_top_face = [&](const Eigen::Vector3d& p) {
    return p.z() > size.z() - 1e-4 && std::abs(p.x()) < 0.5 * size.x() - 2e-3 &&
           std::abs(p.y()) < 0.5 * size.y() - 2e-3;
  };
  int holey_on_top = 0, truth_on_top = 0;
  for (const Eigen::Vector3f& p : holey.points_G) {
    const Eigen::Vector3d q = to_object(p);
    ASSERT_NEAR(CuboidSignedDistance(q, size), 0.0, 1e-4) << q.transpose();
    holey_on_top += on_top_face(q);
  }
  for (const Eigen::Vector3f& p : truth.points_G) {
    const Eigen::Vector3d q = to_object(p);
    ASSERT_NEAR(CuboidSignedDistance(q, size), 0.0, 1e-4) << q.transpose();
    truth_on_top += on_top_face(q);
  }
  EXPECT_EQ(holey_on_top, 0);  // the top is cut off
  EXPECT_GT(truth_on_top, 100);

  // The claw hole centres are in the clouds' frame: the holey cloud is
  // empty around each, the truth is not around the first (on the +x face).
  for (size_t i = 0; i < protocol["claw_hole_centres"].size(); ++i) {
    const nlohmann::json& c = protocol["claw_hole_centres"][i];
    const Eigen::Vector3d centre(c[0], c[1], c[2]);
    int holey_near = 0, truth_near = 0;
    auto near = [&](const Eigen::Vector3f& p) { return (p.cast<double>() - centre).norm() < 0.008; };
    for (const Eigen::Vector3f& p : holey.points_G) holey_near += near(p);
    for (const Eigen::Vector3f& p : truth.points_G) truth_near += near(p);
    EXPECT_EQ(holey_near, 0) << "hole " << i;
    if (i == 0) {
      EXPECT_GT(truth_near, 20);
    }
  }
}

TEST_F(SynthCliTest, ProtocolIsDeterministic) {
  auto run_into = [](const fs::path& out, const std::string& seed) {
    return RunSynth({"--protocol", "paper", "--shape", "cylinder", "--size", "0.06x0.06x0.1", "--grasp",
                     "top-oblique", "--seed", seed, "--points", "5000", "-o", out.string()});
  };
  ASSERT_EQ(run_into(dir_ / "a", "7"), 0);
  ASSERT_EQ(run_into(dir_ / "b", "7"), 0);
  ASSERT_EQ(run_into(dir_ / "c", "8"), 0);
  for (const char* name : {"holey.ply", "gt_cloud.ply", "protocol.json"}) {
    const std::string a = FileBytes(dir_ / "a" / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_EQ(a, FileBytes(dir_ / "b" / name)) << name;
    EXPECT_NE(a, FileBytes(dir_ / "c" / name)) << name;
  }
  const nlohmann::json protocol = ReadJson(dir_ / "a" / "protocol.json");
  EXPECT_EQ(protocol["shape"], "cylinder");
  EXPECT_EQ(protocol["grasp"], "top-oblique");
  EXPECT_NEAR(protocol["size_m"][0].get<double>(), 0.06, 1e-12);
  EXPECT_NEAR(protocol["size_m"][2].get<double>(), 0.1, 1e-12);
}

// Every file synth writes is refused without --force, the claw's link
// meshes included (DIR/claw/palm.ply used to be overwritten), and before
// anything is written.
TEST_F(SynthCliTest, RefusesToOverwriteAClawMeshWithoutForce) {
  fs::create_directories(dir_ / "claw");
  std::ofstream(dir_ / "claw" / "palm.ply") << "precious";
  EXPECT_EQ(RunSynth({"--shape", "sphere", "--frames", "1", "-o", dir_.string()}), 1);
  EXPECT_EQ(FileBytes(dir_ / "claw" / "palm.ply"), "precious");
  EXPECT_FALSE(fs::exists(dir_ / "recording.lcmlog"));
  EXPECT_FALSE(fs::exists(dir_ / "claw" / "claw.json"));
  EXPECT_EQ(RunSynth({"--shape", "sphere", "--frames", "1", "--force", "-o", dir_.string()}), 0);
  EXPECT_NE(FileBytes(dir_ / "claw" / "palm.ply"), "precious");
  EXPECT_NO_THROW(io::ReadMesh((dir_ / "claw" / "palm.ply").string()));
}

// A dangling symlink as an output used to be followed; it is refused
// without --force, and no temporary file is left anywhere.
TEST_F(SynthCliTest, RefusesASymlinkAsAnOutputWithoutForce) {
  fs::create_directories(dir_ / "elsewhere");
  fs::create_symlink(dir_ / "elsewhere" / "scene.json", dir_ / "scene.json");
  EXPECT_EQ(RunSynth({"--shape", "sphere", "--frames", "1", "-o", dir_.string()}), 1);
  EXPECT_FALSE(fs::exists(dir_ / "elsewhere" / "scene.json"));
  EXPECT_FALSE(fs::exists(dir_ / "recording.lcmlog"));
  const Args protocol = {"--protocol", "paper", "--shape", "sphere",
                         "--points",   "2000",  "-o",      (dir_ / "p").string()};
  fs::create_directories(dir_ / "p");
  fs::create_symlink(dir_ / "elsewhere" / "holey.ply", dir_ / "p" / "holey.ply");
  EXPECT_EQ(RunSynth(protocol), 1);
  EXPECT_FALSE(fs::exists(dir_ / "elsewhere" / "holey.ply"));
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

TEST_F(SynthCliTest, ProtocolRefusesToOverwriteWithoutForce) {
  const std::string out = dir_.string();
  const Args first = {"--protocol", "paper", "--shape", "sphere", "--points", "2000", "-o", out};
  ASSERT_EQ(RunSynth(first), 0);
  const std::string holey = FileBytes(dir_ / "holey.ply");
  const Args second = {"--protocol", "paper", "--shape", "sphere", "--points", "3000", "-o", out};
  EXPECT_EQ(RunSynth(second), 1);
  EXPECT_EQ(FileBytes(dir_ / "holey.ply"), holey);
  Args forced = second;
  forced.push_back("--force");
  EXPECT_EQ(RunSynth(forced), 0);
  EXPECT_GT(FileBytes(dir_ / "holey.ply").size(), holey.size());
}

// --slip-mm (object_slip.hpp) end to end.
namespace slip {

// The log's events as (channel, bytes), in order.
std::vector<std::pair<std::string, std::string>> LogEvents(const fs::path& path) {
  std::vector<std::pair<std::string, std::string>> events;
  lcm::LogFile log(path.string(), "r");
  EXPECT_TRUE(log.good()) << path;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    events.emplace_back(event->channel, std::string(static_cast<const char*>(event->data), event->datalen));
  }
  return events;
}

Eigen::Vector3d Vec3(const nlohmann::json& j) {
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

// 40 frames (1.3 s): a slide starting at 70 % still ends before the last.
const std::vector<std::string> kCommon = {"--shape",  "cuboid", "--frames", "40",
                                          "--wall-m", "0",      "--seed",   "6"};

int RunWith(const fs::path& out, std::vector<std::string> extra) {
  Args args(kCommon.begin(), kCommon.end());
  args.insert(args.end(), extra.begin(), extra.end());
  args.push_back("-o");
  args.push_back(out.string());
  return RunSynth(args);
}

}  // namespace slip

TEST_F(SynthCliTest, SlipIsSeededRecordedAndMovesOnlyTheObject) {
  ASSERT_EQ(slip::RunWith(dir_ / "still", {}), 0);
  ASSERT_EQ(slip::RunWith(dir_ / "a", {"--slip-mm", "3"}), 0);
  ASSERT_EQ(slip::RunWith(dir_ / "b", {"--slip-mm", "3"}), 0);
  // Seeded: the same run twice, byte for byte.
  for (const char* name : {"recording.lcmlog", "gt_mesh.ply", "gt_cloud.ply", "scene.json",
                           "gt_mesh_before_slip.ply", "gt_cloud_before_slip.ply"}) {
    const std::string a = FileBytes(dir_ / "a" / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_EQ(a, FileBytes(dir_ / "b" / name)) << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "still" / "gt_cloud_before_slip.ply"));

  // scene.json: exactly the slip the model draws for this seed and span.
  const nlohmann::json scene = ReadJson(dir_ / "a" / "scene.json");
  EXPECT_FALSE(ReadJson(dir_ / "still" / "scene.json").contains("slip"));
  ASSERT_TRUE(scene.contains("slip"));
  const nlohmann::json& s = scene["slip"];
  synth::SlipConfig config;
  config.distance_m = 0.003;
  const synth::ObjectSlip model(config, 6, scene["log"]["first_depth_utime"].get<int64_t>(),
                                scene["log"]["last_depth_utime"].get<int64_t>());
  EXPECT_EQ(s["distance_mm"].get<double>(), 3.0);
  EXPECT_EQ(slip::Vec3(s["direction_G"]), model.direction_G());
  EXPECT_EQ(slip::Vec3(s["displacement_G_m"]), model.Displacement_G());
  EXPECT_EQ(s["start_utime"].get<int64_t>(), model.start_utime());
  EXPECT_EQ(s["end_utime"].get<int64_t>(), model.end_utime());
  EXPECT_EQ(s["duration_s"].get<double>(), 0.3);
  const Eigen::Vector3d d = slip::Vec3(s["displacement_G_m"]);
  EXPECT_NEAR(d.norm(), 0.003, 1e-12);

  // The truth: where the object ends, the same samples as grasped beside it.
  const ObjectCloud after = io::ReadCloudPly((dir_ / "a" / "gt_cloud.ply").string());
  const ObjectCloud before = io::ReadCloudPly((dir_ / "a" / "gt_cloud_before_slip.ply").string());
  EXPECT_EQ(FileBytes(dir_ / "a" / "gt_cloud_before_slip.ply"), FileBytes(dir_ / "still" / "gt_cloud.ply"));
  ASSERT_EQ(after.size(), before.size());
  double worst = 0.0;
  for (size_t i = 0; i < after.size(); ++i) {
    worst =
        std::max(worst, (after.points_G[i].cast<double>() - before.points_G[i].cast<double>() - d).norm());
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(after.normals_G, before.normals_G);
  const TriangleMesh mesh_after = io::ReadMesh((dir_ / "a" / "gt_mesh.ply").string());
  const TriangleMesh mesh_before = io::ReadMesh((dir_ / "a" / "gt_mesh_before_slip.ply").string());
  ASSERT_EQ(mesh_after.vertices.size(), mesh_before.vertices.size());
  EXPECT_TRUE(mesh::Bounds(mesh_after).min().isApprox(mesh::Bounds(mesh_before).min() + d, 1e-6));
  EXPECT_EQ(FileBytes(dir_ / "a" / "gt_mesh_before_slip.ply"), FileBytes(dir_ / "still" / "gt_mesh.ply"));

  // The log: the claw's states untouched; the frames those of the still
  // object until the slide starts, different once it is over.
  const auto still = slip::LogEvents(dir_ / "still" / "recording.lcmlog");
  const auto slipped = slip::LogEvents(dir_ / "a" / "recording.lcmlog");
  ASSERT_EQ(still.size(), slipped.size());
  const int first_moved = s["first_frame_moved"].get<int>();
  const int first_settled = s["first_frame_settled"].get<int>();
  EXPECT_GE(first_moved, 11);  // 30 % of 39 frames' span, and more
  EXPECT_LE(first_settled, 39);
  EXPECT_LE(first_settled - first_moved, 10);  // 0.3 s at 30 Hz
  const io::ChannelNames channels;
  int frame = 0, same_before = 0, differ_after = 0, states = 0;
  for (size_t i = 0; i < still.size(); ++i) {
    ASSERT_EQ(still[i].first, slipped[i].first);
    if (still[i].first == channels.depth) {
      if (frame < first_moved) same_before += still[i].second == slipped[i].second;
      if (frame >= first_settled) differ_after += still[i].second != slipped[i].second;
      ++frame;
    } else if (still[i].first == channels.gripper_state) {
      EXPECT_EQ(still[i].second, slipped[i].second);
      ++states;
    }
  }
  EXPECT_EQ(frame, 40);
  EXPECT_GT(states, 100);
  EXPECT_EQ(same_before, first_moved);
  EXPECT_EQ(differ_after, 40 - first_settled);
}

TEST_F(SynthCliTest, ZeroSlipChangesNothing) {
  ASSERT_EQ(slip::RunWith(dir_ / "default", {}), 0);
  ASSERT_EQ(slip::RunWith(dir_ / "zero", {"--slip-mm", "0"}), 0);
  size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir_ / "default")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), dir_ / "default");
    EXPECT_EQ(FileBytes(entry.path()), FileBytes(dir_ / "zero" / rel)) << rel;
    ++files;
  }
  size_t zero_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir_ / "zero")) {
    zero_files += entry.is_regular_file();
  }
  EXPECT_GE(files, 6u);
  EXPECT_EQ(files, zero_files);
}

TEST_F(SynthCliTest, BadSlipIsRefused) {
  for (const char* bad : {"-1", "20.5", "abc", "nan", ""}) {
    EXPECT_EQ(slip::RunWith(dir_, {"--slip-mm", bad}), 2) << bad;
  }
  testing::internal::CaptureStderr();
  EXPECT_EQ(slip::RunWith(dir_, {"--slip-mm", "25"}), 2);
  const std::string message = testing::internal::GetCapturedStderr();
  EXPECT_NE(message.find("--slip-mm '25': out of range, expected 0..20 mm"), std::string::npos) << message;
  EXPECT_EQ(RunSynth({"--protocol", "paper", "--shape", "cuboid", "--slip-mm", "3", "-o", dir_.string()}), 2);
  EXPECT_EQ(RunSynth({"--grasps", "cuboid,sphere", "--slip-mm", "3", "-o", dir_.string()}), 2);
  EXPECT_EQ(RunSynth({"--shape", "cuboid", "--slip-mm", "-o", dir_.string()}), 2);
  EXPECT_FALSE(fs::exists(dir_));
}

// Options the grasps' scenes do not take are refused with --grasps, not
// dropped; a bad --speed-variation is refused.
TEST_F(SynthCliTest, OneGraspOptionsAreRefusedWithGraspsAndBadSpeedVariation) {
  for (const std::vector<std::string>& extra :
       std::vector<std::vector<std::string>>{{"--hand-eye-error", "3,1"},
                                             {"--pose-noise", "0.5,0.2"},
                                             {"--clock-offset-ms", "15"},
                                             {"--speed-variation", "0.5"}}) {
    std::vector<std::string> args = {"--grasps", "cuboid,sphere"};
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), {"-o", dir_.string()});
    testing::internal::CaptureStderr();
    EXPECT_EQ(RunSynth(args), 2) << extra[0];
    const std::string message = testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find("not to --grasps"), std::string::npos) << message;
  }
  for (const char* bad : {"-0.1", "0.95", "x"}) {
    EXPECT_EQ(RunSynth({"--shape", "cuboid", "--speed-variation", bad, "-o", dir_.string()}), 2) << bad;
  }
  EXPECT_FALSE(fs::exists(dir_));
}

}  // namespace
}  // namespace graspfill::cli
