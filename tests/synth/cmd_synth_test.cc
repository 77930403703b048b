// `graspfill synth` end to end: arguments, the files it writes, and the
// recording read back with LCM's own log reader and graspfill's decoders.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "graspfill/synth/mesh_sampling.hpp"
#include "graspfill/synth/shapes.hpp"

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;

class SynthCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("graspfill_synth_cli_test_" + std::to_string(::getpid()) + "_" +
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
  ASSERT_EQ(RunSynth({"--shape", "cylinder", "--grasp", "top-oblique", "--frames", "4",
                      "--seed", "5", "-o", out}),
            0);
  for (const char* name : {"recording.lcmlog", "gt_mesh.ply", "gt_cloud.ply", "claw.ply",
                           "scene.json", "claw/claw.json"}) {
    EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
  }

  // The log: depth and gripper events in time order, stamped with utime.
  const io::ChannelNames channels;
  lcm::LogFile log((dir_ / "recording.lcmlog").string(), "r");
  ASSERT_TRUE(log.good());
  int depth_events = 0, gripper_events = 0;
  int64_t last_timestamp = 0;
  DepthFrame frame;
  GripperState state;
  std::string error;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    EXPECT_GE(event->timestamp, last_timestamp);
    last_timestamp = event->timestamp;
    if (event->channel == channels.depth) {
      ASSERT_TRUE(io::DecodeDepthImage(event->data, event->datalen, &frame, &error)) << error;
      EXPECT_EQ(frame.utime, event->timestamp);
      EXPECT_EQ(frame.intrinsics, CameraIntrinsics{});
      int valid = 0;
      for (float z : frame.depth_m) valid += z > 0.0f;
      EXPECT_GT(valid, 0.9 * frame.depth_m.size());
      ++depth_events;
    } else if (event->channel == channels.gripper_state) {
      ASSERT_TRUE(io::DecodeGripperState(event->data, event->datalen,
                                         Eigen::Isometry3d::Identity(), &state, &error))
          << error;
      EXPECT_EQ(state.utime, event->timestamp);
      EXPECT_GT(state.opening_m, 0.03);
      ++gripper_events;
    } else {
      ADD_FAILURE() << "unexpected channel " << event->channel;
    }
  }
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
  const Eigen::AlignedBox3d mesh_box = synth::Bounds(gt_mesh);
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
  EXPECT_TRUE(synth::Bounds(posed).isApprox(synth::Bounds(claw_ply), 1e-5));
  EXPECT_NEAR(synth::SurfaceArea(posed), synth::SurfaceArea(claw_ply), 1e-6);
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

}  // namespace
}  // namespace graspfill::cli
