// SPDX-License-Identifier: BSD-3-Clause
// The replay session, composed (log -> sequencer -> per grasp: repair ->
// PLY -> publish), on the bundled recording and on a two-grasp recording
// made from it: the output's bytes are the parts' own, every grasp's model
// has its file, and the two error policies of a delivery hold (an earlier
// grasp's failed repair still writes its model; the output's stops).
#include "module/replay_session.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "graspfill/io/ply.hpp"
#include "module/cloud_repair.hpp"
#include "module/sequencer_feed.hpp"
#include "module/session_loop.hpp"
#include "sinks/lcm_log_writer.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

const std::string kBundled = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";

std::filesystem::path ScratchDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::path(GRASPFILL_BINARY_DIR) / "test_scratch" / ("replay_session_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

ReplaySessionConfig Config(const std::string& log, const std::filesystem::path& output) {
  ReplaySessionConfig config;
  config.log.path = log;
  config.output_path = output.string();
  config.publish = false;
  return config;
}

// The bundled recording as two grasps: its gripper states before the
// middle of their time span numbered 1, the rest 2 (the robot's grasp
// signal, gripper_state_t.grasp_id); every other event as it was.
void WriteTwoGraspRecording(const std::string& path) {
  const io::ChannelNames channels;
  std::vector<io::LogEvent> events;
  int64_t first_utime = -1, last_utime = -1;
  io::LcmLogReader reader(kBundled);
  for (io::LogEvent e; reader.Next(&e) == io::LogReadResult::kEvent;) {
    if (e.channel == channels.gripper_state) {
      if (first_utime < 0) first_utime = e.timestamp_us;
      last_utime = e.timestamp_us;
    }
    events.push_back(e);
  }
  const int64_t middle_utime = (first_utime + last_utime) / 2;
  LcmLogWriter writer(path);
  for (const io::LogEvent& e : events) {
    if (e.channel != channels.gripper_state) {
      writer.Write(e.channel, e.timestamp_us, e.data);
      continue;
    }
    GripperState state;
    std::string error;
    ASSERT_TRUE(
        io::DecodeGripperState(e.data.data(), e.data.size(), Eigen::Isometry3d::Identity(), &state, &error))
        << error;
    state.grasp_id = e.timestamp_us < middle_utime ? 1 : 2;
    writer.Write(e.channel, e.timestamp_us, io::EncodeGripperState(state));
  }
  writer.Close();
}

// The replay from its parts, without the session: the loop into a
// sequencer, the last grasp's model repaired with what the camera saw,
// then written.
void WriteReferenceOutput(const std::string& log, const std::string& path) {
  LcmLogSource::Config source_config;
  source_config.path = log;
  source_config.session_events = true;
  LcmLogSource source(source_config);
  SequencerFeed feed(
      [](const std::optional<io::SessionDescription>&) {
        return std::make_unique<GraspSequencer>(PipelineConfig{}, claw::ClawModel::ThreeFinger(),
                                                GraspSequencerConfig{}, nullptr);
      },
      false);
  ASSERT_EQ(SessionLoop(SessionLoopLimits{}).Run(&source, &feed), LoopEnd::kEndOfStream);
  ObjectCloud cloud = feed.sequencer()->Finish();
  RepairObjectCloud(GripperFrameRepairConfig(), &cloud, &feed.sequencer()->pipeline().visibility());
  io::WriteCloudPly(path, cloud);
}

TEST(ReplaySession, TheOutputIsTheBytesOfItsParts) {
  const std::filesystem::path dir = ScratchDir("bytes");
  ReplaySession session(Config(kBundled, dir / "model.ply"));
  const ReplayResult result = session.Run();
  ASSERT_EQ(result.end, ReplayEnd::kDone) << result.error;
  ASSERT_EQ(result.grasps.size(), 1u);
  const GraspDelivery& output = result.grasps[0];
  EXPECT_EQ(output.model, DeliveredModel::kOutput);
  EXPECT_EQ(output.path, (dir / "model.ply").string());
  ASSERT_TRUE(output.repair.has_value());
  EXPECT_EQ(output.RepairStatusText(), output.repair->StatusText());
  EXPECT_GT(output.points, output.fused_points);  // the repair added some
  EXPECT_EQ(result.output.size(), output.points);
  EXPECT_FALSE(result.session.has_value());  // the bundled log has no description
  EXPECT_EQ(result.stats.frames_in, 36);
  ASSERT_NE(session.pipeline(), nullptr);

  WriteReferenceOutput(kBundled, (dir / "reference.ply").string());
  const std::string written = FileBytes(dir / "model.ply");
  EXPECT_GT(written.size(), 1000u);
  EXPECT_TRUE(written == FileBytes(dir / "reference.ply"));
}

TEST(ReplaySession, EveryGraspsModelHasItsFileBesideTheOutput) {
  const std::filesystem::path dir = ScratchDir("grasps");
  const std::string log = (dir / "two_grasps.lcmlog").string();
  WriteTwoGraspRecording(log);
  ReplaySessionConfig config = Config(log, dir / "model.ply");
  config.keep_output_fused = true;
  ReplaySession session(config);
  const ReplayResult result = session.Run();
  ASSERT_EQ(result.end, ReplayEnd::kDone) << result.error;
  ASSERT_EQ(result.grasps.size(), 2u);
  EXPECT_EQ(result.counters.grasps_completed, 2);
  const GraspDelivery& first = result.grasps[0];
  const GraspDelivery& last = result.grasps[1];
  EXPECT_EQ(first.model, DeliveredModel::kEarlierGrasp);
  EXPECT_EQ(first.grasp_id, 1);
  EXPECT_EQ(first.path, (dir / "model.grasp1.ply").string());
  EXPECT_EQ(last.model, DeliveredModel::kOutput);
  EXPECT_EQ(last.grasp_id, 2);
  EXPECT_EQ(last.path, (dir / "model.ply").string());
  for (const GraspDelivery& g : result.grasps) {
    EXPECT_EQ(g.step, DeliveryStep::kDelivered);
    EXPECT_TRUE(g.repair.has_value()) << g.path;
    EXPECT_GT(g.fused_points, 1000u) << g.path;
    const ObjectCloud read = io::ReadCloudPly(g.path);
    EXPECT_EQ(read.size(), g.points) << g.path;
  }
  // The output as fused is kept for a before-and-after picture.
  ASSERT_TRUE(result.output_fused.has_value());
  EXPECT_EQ(result.output_fused->size(), last.fused_points);
  EXPECT_EQ(result.output.size(), last.points);
}

TEST(ReplaySession, AFailedRepairWritesAnEarlierGraspButStopsTheOutput) {
  const std::filesystem::path dir = ScratchDir("repair_fails");
  const std::string log = (dir / "two_grasps.lcmlog").string();
  WriteTwoGraspRecording(log);
  ReplaySessionConfig config = Config(log, dir / "model.ply");
  config.repair_config.safe_bound_voxel_m = -1.0;  // every repair throws on it
  ReplaySession session(config);
  const ReplayResult result = session.Run();
  EXPECT_EQ(result.end, ReplayEnd::kDeliveryFailed);
  ASSERT_EQ(result.grasps.size(), 2u);
  // The earlier grasp: written (and would be published) as fused.
  const GraspDelivery& first = result.grasps[0];
  EXPECT_EQ(first.step, DeliveryStep::kDelivered);
  EXPECT_FALSE(first.repair.has_value());
  EXPECT_NE(first.repair_error.find("safe_bound_voxel_m"), std::string::npos) << first.repair_error;
  EXPECT_EQ(first.RepairStatusText(), "failed: " + first.repair_error);
  EXPECT_EQ(first.points, first.fused_points);
  EXPECT_EQ(io::ReadCloudPly(first.path).size(), first.fused_points);
  // The output: nothing written in place of the repaired model asked for.
  const GraspDelivery& last = result.grasps[1];
  EXPECT_EQ(last.step, DeliveryStep::kRepairFailed);
  EXPECT_FALSE(last.repair_error.empty());
  EXPECT_FALSE(std::filesystem::exists(dir / "model.ply"));
}

TEST(ReplaySession, AnEarlierGraspsPathInTheWayStopsBeforeTheOutput) {
  const std::filesystem::path dir = ScratchDir("path_in_the_way");
  const std::string log = (dir / "two_grasps.lcmlog").string();
  WriteTwoGraspRecording(log);
  std::ofstream(dir / "model.grasp1.ply") << "not ours";
  ReplaySessionConfig config = Config(log, dir / "model.ply");
  config.repair = false;
  ReplaySession session(config);
  const ReplayResult result = session.Run();
  EXPECT_EQ(result.end, ReplayEnd::kDeliveryFailed);
  ASSERT_EQ(result.grasps.size(), 1u);
  EXPECT_EQ(result.grasps[0].step, DeliveryStep::kWriteFailed);
  EXPECT_NE(result.grasps[0].write_error.find("pass --force"), std::string::npos)
      << result.grasps[0].write_error;
  EXPECT_EQ(FileBytes(dir / "model.grasp1.ply"), "not ours");
  EXPECT_FALSE(std::filesystem::exists(dir / "model.ply"));
}

TEST(ReplaySession, ALogWithoutDepthOnTheChannelEndsSo) {
  const std::filesystem::path dir = ScratchDir("no_depth");
  ReplaySessionConfig config = Config(kBundled, dir / "model.ply");
  config.log.channels.depth = "NOT_THE_DEPTH";
  ReplaySession session(config);
  const ReplayResult result = session.Run();
  EXPECT_EQ(result.end, ReplayEnd::kNoDepthFrames);
  EXPECT_GT(result.events_read, 0);
  EXPECT_FALSE(result.channels_seen.empty());
  EXPECT_TRUE(result.grasps.empty());
  EXPECT_FALSE(std::filesystem::exists(dir / "model.ply"));
}

TEST(ReplaySession, GraspModelPathNumbersAReusedGraspId) {
  EXPECT_EQ(GraspModelPath("out/model.ply", 3, 1), "out/model.grasp3.ply");
  EXPECT_EQ(GraspModelPath("out/model.ply", 3, 2), "out/model.grasp3-2.ply");
  EXPECT_EQ(GraspModelPath("model.ply", 0, 1), "model.grasp0.ply");
}

}  // namespace
}  // namespace graspfill::rt
