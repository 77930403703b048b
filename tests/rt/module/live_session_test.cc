// SPDX-License-Identifier: BSD-3-Clause
// The live session, composed (source -> module -> repair -> publisher, with
// the recorder beside), on LCM's in-process memq:// provider, fed from the
// bundled recording: `live --record` then `replay` of the record gives the
// live session's final cloud, and the status tells the bus time and state.
#include "module/live_session.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <vector>

#include "../../io/file_size_limit.hpp"
#include "../test_cloud.hpp"
#include "claw_option.hpp"
#include "graspfill/io/messages.hpp"
#include "module/cloud_repair.hpp"
#include "module/sequencer_feed.hpp"
#include "module/session_loop.hpp"
#include "sources/lcm_log_source.hpp"

namespace graspfill::rt {
namespace {

const std::string kBundled = std::string(GRASPFILL_SOURCE_DIR) + "/replay/default/recording.lcmlog";

LcmLogSource::Config LogConfig(const std::string& path) {
  LcmLogSource::Config config;
  config.path = path;
  config.session_events = true;
  return config;
}

// The replay path (ReplaySession's, without its files): the session loop
// into a sequencer, then the repair with what the camera saw.
ObjectCloud ReplayFinalCloud(const std::string& path, std::optional<io::SessionDescription>* session) {
  LcmLogSource source(LogConfig(path));
  SequencerFeed feed(
      [](const std::optional<io::SessionDescription>&) {
        return std::make_unique<GraspSequencer>(PipelineConfig{}, claw::ClawModel::ThreeFinger(),
                                                GraspSequencerConfig{}, nullptr);
      },
      false);
  EXPECT_EQ(SessionLoop(SessionLoopLimits{}).Run(&source, &feed), LoopEnd::kEndOfStream)
      << feed.first_error();
  if (session) *session = feed.session();
  ObjectCloud cloud = feed.sequencer()->Finish();
  RepairObjectCloud(GripperFrameRepairConfig(repair::RepairConfig{}), &cloud,
                    &feed.sequencer()->pipeline().visibility());
  return cloud;
}

// What `graspfill live --claw three-finger` heads its recording with.
io::SessionDescription Description() {
  io::SessionDescription session;
  session.software_version = io::SoftwareVersion();
  cli::DescribeBuiltinClaw("three-finger", claw::ProceduralClawConfig{}, &session);
  return session;
}

// Every cloud published on `channel`, decoded as a planner would.
void SubscribeClouds(lcm::LCM* bus, const std::string& channel, std::vector<ObjectCloud>* clouds) {
  bus->subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, std::vector<ObjectCloud>* out) {
        ObjectCloud c;
        std::string error;
        ASSERT_TRUE(io::DecodeObjectCloud(rbuf->data, rbuf->data_size, &c, &error)) << error;
        out->push_back(std::move(c));
      },
      clouds);
}

TEST(LiveSession, RecordThenReplayGivesTheSessionsFinalCloud) {
  const std::filesystem::path dir =
      std::filesystem::path(GRASPFILL_BINARY_DIR) / "test_scratch" / "live_session_record";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string record = (dir / "session.lcmlog").string();

  LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.module.frame_queue_capacity = 1000;  // no drops: the record is the session
  config.module.state_queue_capacity = 10000;
  config.module.extract_every_n_frames = 10;
  config.repair_config = GripperFrameRepairConfig(repair::RepairConfig{});
  config.record.path = record;
  config.record.queue_capacity = 10000;
  LiveSession live(config);

  // Every cloud the session publishes, decoded as a planner would.
  std::vector<ObjectCloud> clouds;
  std::vector<io::ModuleStatus> statuses;
  lcm::LCM* bus = live.publisher().lcm_instance();
  SubscribeClouds(bus, config.channels.object_cloud, &clouds);
  bus->subscribeFunction(
      config.channels.status,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, std::vector<io::ModuleStatus>* out) {
        io::ModuleStatus s;
        std::string error;
        ASSERT_TRUE(io::DecodeModuleStatus(rbuf->data, rbuf->data_size, &s, &error)) << error;
        out->push_back(std::move(s));
      },
      &statuses);

  live.Begin(claw::ClawModel::ThreeFinger(), Description());
  LcmLogSource source(LogConfig(kBundled));
  const LiveSessionSummary summary = live.Run(&source);
  while (bus->handleTimeout(50) > 0) {
  }
  EXPECT_EQ(summary.module.frames_dropped, 0);
  EXPECT_EQ(summary.records_dropped, 0);
  EXPECT_GT(summary.records_written, 36);
  ASSERT_FALSE(clouds.empty());
  const ObjectCloud& live_final = clouds.back();
  EXPECT_TRUE(live_final.is_final);
  EXPECT_GT(live_final.size(), 1000u);
  for (size_t i = 0; i + 1 < clouds.size(); ++i) EXPECT_FALSE(clouds[i].is_final);

  // The record opens with the session description, and replays to the
  // live session's final cloud, point for point (as the bus carries it:
  // packed, test_cloud.hpp's AsOnTheWire).
  std::optional<io::SessionDescription> recorded_session;
  const ObjectCloud replayed = ReplayFinalCloud(record, &recorded_session);
  ASSERT_TRUE(recorded_session.has_value());
  EXPECT_EQ(recorded_session->claw_name, "three-finger");
  EXPECT_EQ(replayed.size(), live_final.size());
  EXPECT_TRUE(testing::AsOnTheWire(replayed).points_G == live_final.points_G);
  // And it held what was received: the original replays to the same cloud.
  EXPECT_TRUE(testing::AsOnTheWire(ReplayFinalCloud(kBundled, nullptr)).points_G == live_final.points_G);

  // The last status: bus time of the newest frame, fused counts, a state.
  ASSERT_FALSE(statuses.empty());
  const io::ModuleStatus& status = statuses.back();
  int64_t last_depth_utime = 0;
  LcmLogSource again(LogConfig(kBundled));
  for (SourceEvent e; again.Next(&e) == FrameResult::kOk;) {
    if (e.kind == SourceEvent::Kind::kDepth) last_depth_utime = e.depth.utime;
  }
  EXPECT_EQ(status.utime, last_depth_utime);
  EXPECT_EQ(status.frames_used, summary.module.pipeline.frames_integrated);
  EXPECT_EQ(status.state_code, io::ModuleState::kFusing);
  EXPECT_EQ(status.state, "fusing");
  EXPECT_EQ(status.grasps_completed, 1);
  EXPECT_GE(status.repairs_done, 1);
  EXPECT_EQ(status.decode_errors, 0);

  // Every cloud carries its age, from its newest frame's arrival; the
  // status and the summary count them all and sum up their latencies.
  for (const ObjectCloud& c : clouds) {
    double to_cloud = -1, to_repaired = -1;
    for (const StageTiming& t : c.timings) {
      if (t.stage == "latency_frame_to_cloud") to_cloud = t.ms;
      if (t.stage == "latency_frame_to_repaired") to_repaired = t.ms;
    }
    EXPECT_GT(to_cloud, 0.0) << "cloud seq " << c.seq;
    EXPECT_GE(to_repaired, to_cloud) << "cloud seq " << c.seq;
  }
  EXPECT_EQ(summary.clouds_published, static_cast<int64_t>(clouds.size()));
  EXPECT_EQ(summary.latency_ms.count, clouds.size());
  EXPECT_EQ(status.clouds_published, static_cast<int64_t>(clouds.size()));
  EXPECT_GT(status.latency_ms_p50, 0.0);
  EXPECT_LE(status.latency_ms_p50, status.latency_ms_p99);
  EXPECT_LE(status.latency_ms_p99, status.latency_ms_max);
  // The final is repaired in full, the others are updates of full repairs
  // run behind (or fused, before the first of those landed).
  ASSERT_TRUE(summary.repair.has_value());
  EXPECT_GE(summary.repair->full_published, 1);
  EXPECT_EQ(summary.repair->updates + summary.repair->full_published, summary.repair->repaired);
  EXPECT_EQ(summary.repair->repaired + summary.repair->unrepaired + summary.repair->failed,
            summary.repair->published);
  EXPECT_EQ(status.repair_updates, summary.repair->updates);
  EXPECT_GT(status.rss_mb, 10.0);
}

// Begin's pipeline replaces the one the session was made with (live sets
// a session description's box and voxel there, known only once the session
// is open): a box cut at 10 cm keeps the bundled object's top (up to 18.6 cm)
// out of every cloud.
TEST(LiveSession, BeginsWithThePipelineItIsGiven) {
  LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.module.frame_queue_capacity = 1000;
  config.module.state_queue_capacity = 10000;
  config.repair = false;  // the fused cloud itself
  LiveSession live(config);
  std::vector<ObjectCloud> clouds;
  SubscribeClouds(live.publisher().lcm_instance(), config.channels.object_cloud, &clouds);

  PipelineConfig pipeline = config.module.pipeline;
  constexpr double kTopZ_m = 0.10;
  pipeline.workspace.max_G.z() = kTopZ_m;
  live.Begin(claw::ClawModel::ThreeFinger(), Description(), pipeline);
  LcmLogSource source(LogConfig(kBundled));
  live.Run(&source);
  while (live.publisher().lcm_instance()->handleTimeout(50) > 0) {
  }
  ASSERT_FALSE(clouds.empty());
  const ObjectCloud& final_cloud = clouds.back();
  EXPECT_GT(final_cloud.size(), 1000u);
  float top_z_m = 0.0f;
  for (const Eigen::Vector3f& p : final_cloud.points_G) top_z_m = std::max(top_z_m, p.z());
  // Within the truncation band (4 voxels of 2 mm) of the box's top.
  EXPECT_LT(top_z_m, kTopZ_m + 0.01);
}

// A full disk while recording (issue 36; RLIMIT_FSIZE here, a real
// ENOSPC in live_record_faults.sh): the recording stops and keeps what it
// wrote, the status says so, and the session fuses on to the same final
// cloud as the recording's replay.
TEST(LiveSession, AFullDiskStopsTheRecordingNotTheSession) {
  const std::filesystem::path dir =
      std::filesystem::path(GRASPFILL_BINARY_DIR) / "test_scratch" / "live_session_full_disk";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string record = (dir / "session.lcmlog").string();

  LiveSessionConfig config;
  config.lcm_url = "memq://";
  config.module.frame_queue_capacity = 1000;  // no drops: the cloud is the recording's
  config.module.state_queue_capacity = 10000;
  config.module.extract_every_n_frames = 10;
  config.repair_config = GripperFrameRepairConfig(repair::RepairConfig{});
  config.record.path = record;
  config.record.queue_capacity = 10000;
  config.record.queue_bytes = int64_t{1} << 30;
  LiveSession live(config);
  std::vector<ObjectCloud> clouds;
  std::vector<io::ModuleStatus> statuses;
  lcm::LCM* bus = live.publisher().lcm_instance();
  SubscribeClouds(bus, config.channels.object_cloud, &clouds);
  bus->subscribeFunction(
      config.channels.status,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, std::vector<io::ModuleStatus>* out) {
        io::ModuleStatus s;
        std::string error;
        ASSERT_TRUE(io::DecodeModuleStatus(rbuf->data, rbuf->data_size, &s, &error)) << error;
        out->push_back(std::move(s));
      },
      &statuses);

  LiveSessionSummary summary;
  {
    graspfill::testing::FileSizeLimit full(256 << 10);
    ASSERT_TRUE(full.ok());
    live.Begin(claw::ClawModel::ThreeFinger(), Description());
    LcmLogSource source(LogConfig(kBundled));
    summary = live.Run(&source);  // does not throw: the recording's failure is reported
  }
  while (bus->handleTimeout(50) > 0) {
  }
  EXPECT_NE(summary.record_failure.find("cannot write log '" + record + "': " + std::strerror(EFBIG)),
            std::string::npos)
      << summary.record_failure;
  EXPECT_GE(summary.records_written, 1);
  EXPECT_GT(summary.records_dropped, 0);
  ASSERT_FALSE(statuses.empty());
  const io::ModuleStatus& status = statuses.back();
  EXPECT_EQ(status.state_code, io::ModuleState::kFusing);
  EXPECT_EQ(status.state, "fusing: recording stopped: " + summary.record_failure);
  // Fusion went on: the same final cloud as the recording's replay.
  ASSERT_FALSE(clouds.empty());
  EXPECT_TRUE(clouds.back().is_final);
  EXPECT_EQ(summary.module.frames_dropped, 0);
  EXPECT_TRUE(testing::AsOnTheWire(ReplayFinalCloud(kBundled, nullptr)).points_G == clouds.back().points_G);
  // The log keeps what was written before: whole events, readable.
  LcmLogSource kept(LogConfig(record));
  int64_t events = 0;
  for (SourceEvent e; kept.Next(&e) == FrameResult::kOk;) ++events;
  EXPECT_EQ(events, summary.records_written + 1);  // and the session description
  EXPECT_FALSE(kept.truncated());
}

}  // namespace
}  // namespace graspfill::rt
