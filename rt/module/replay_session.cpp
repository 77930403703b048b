// SPDX-License-Identifier: BSD-3-Clause
#include "module/replay_session.hpp"

#include <chrono>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <utility>

#include "graspfill/io/cloud_file.hpp"
#include "graspfill/io/output_path.hpp"
#include "module/cloud_repair.hpp"
#include "module/error_text.hpp"
#include "module/session_loop.hpp"
#include "sources/prefetching_source.hpp"

namespace graspfill::rt {

namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// The log, decoded ahead on a second thread (overlapping the pipeline);
// *log: the log source inside, for its counters once it ended.
std::unique_ptr<FrameSource> OpenLog(LcmLogSource::Config config, const LcmLogSource** log) {
  config.session_events = true;  // the recording's description picks the claw, box and voxel
  auto log_source = std::make_unique<LcmLogSource>(config);  // throws on a bad file
  *log = log_source.get();
  return std::make_unique<PrefetchingSource>(std::move(log_source));
}

}  // namespace

std::string GraspDelivery::RepairStatusText() const {
  if (!repair_error.empty()) return "failed: " + repair_error;
  return repair ? repair->StatusText() : "off";
}

std::string GraspModelPath(const std::string& output_path, int64_t grasp_id, int occurrence) {
  const std::filesystem::path out(output_path);
  std::string name = out.stem().string() + ".grasp" + std::to_string(grasp_id);
  if (occurrence > 1) name += "-" + std::to_string(occurrence);
  return (out.parent_path() / (name + out.extension().string())).string();
}

ReplaySession::ReplaySession(ReplaySessionConfig config)
    : config_(std::move(config)),
      source_(OpenLog(config_.log, &log_)),
      feed_([this](const std::optional<io::SessionDescription>& s) { return MakeSequencer(s); },
            config_.skip_bad_events) {
  config_.repair_config = GripperFrameRepairConfig(config_.repair_config);
}

ReplaySession::~ReplaySession() = default;

const Pipeline* ReplaySession::pipeline() const {
  const GraspSequencer* sequencer = feed_.sequencer();
  return sequencer != nullptr ? &sequencer->pipeline() : nullptr;
}

std::unique_ptr<GraspSequencer> ReplaySession::MakeSequencer(
    const std::optional<io::SessionDescription>& session) {
  PipelineConfig pipeline = config_.pipeline;
  if (session && session->workspace_G && !config_.workspace_fixed) {
    pipeline.workspace.min_G = session->workspace_G->min();
    pipeline.workspace.max_G = session->workspace_G->max();
  }
  if (session) {
    // What of it is used keeps the config file's limits (as on the bus).
    io::SessionDescription used = *session;
    if (config_.voxel_fixed) used.voxel_m = 0.0;
    if (config_.workspace_fixed) used.workspace_G.reset();
    if (!config_.log.overrides.T_C_B_from_session) used.T_C_B = Eigen::Isometry3d::Identity();
    std::string why;
    if (!io::SessionWithinLimits(used, &why)) {
      throw std::runtime_error("the recording's session description " + why +
                               " (override it: --voxel-m, --config)");
    }
  }
  if (session && session->voxel_m > 0.0 && !config_.voxel_fixed) {
    pipeline.tsdf.voxel_m = session->voxel_m;
    pipeline.tsdf.sdf_trunc_m = config_.sdf_trunc_voxels * session->voxel_m;
  }
  claw::ClawModel claw = config_.choose_claw ? config_.choose_claw(session) : claw::ClawModel::ThreeFinger();
  return std::make_unique<GraspSequencer>(
      pipeline, std::move(claw), GraspSequencerConfig{},
      [this](const ObjectCloud& cloud, const evidence::VisibilityRecord& seen) {
        ended_.push_back(EndedGrasp{cloud, seen});
      });
}

ReplayResult ReplaySession::Run() {
  if (!source_) throw std::logic_error("ReplaySession::Run twice");
  ReplayResult result;
  SessionLoopLimits limits;
  if (config_.on_progress) {
    limits.on_tick = [this] { config_.on_progress(feed_.depth_events()); };
    limits.tick_ms = config_.progress_period_ms;
  }
  const auto t_start = Clock::now();
  const LoopEnd loop_end = SessionLoop(limits).Run(source_.get(), &feed_);
  result.session = feed_.session();
  result.sessions = feed_.sessions();
  result.late_sessions = feed_.late_sessions();
  result.late_session_utime = feed_.late_session_utime();
  result.bad_events_skipped = feed_.bad_events();
  if (loop_end == LoopEnd::kSinkStopped) {
    result.end = ReplayEnd::kBadEvent;
    result.error = feed_.first_error();
    source_.reset();
    return result;
  }
  result.events_read = log_->events_read();
  result.channels_seen = log_->channels_seen();
  if (log_->partial_last_event()) {
    result.partial_event_bytes = log_->unread_bytes();
  } else if (log_->truncated()) {
    result.end = ReplayEnd::kLogCorrupt;
    result.error = log_->stop_reason();
  }
  source_.reset();  // the log is read: its reader thread ends
  log_ = nullptr;
  if (result.end != ReplayEnd::kDone) return result;
  if (feed_.depth_events() == 0) {
    result.end = ReplayEnd::kNoDepthFrames;
    return result;
  }
  GraspSequencer& sequencer = *feed_.sequencer();  // made: there was a depth event
  const auto t_fused = Clock::now();
  sequencer.Finish();  // the last grasp's model, to the callback like the others
  result.fuse_ms = Ms(t_fused - t_start);
  result.extract_ms = Ms(Clock::now() - t_fused);
  result.stats = sequencer.stats();
  result.counters = sequencer.counters();
  if (result.stats.frames_integrated == 0) {
    result.end =
        result.stats.frames_skipped_refine > 0 ? ReplayEnd::kRefineRejectedEvery : ReplayEnd::kNoPosedFrames;
    return result;
  }

  std::map<int64_t, int> times_seen;  // by grasp id: a robot may reuse ids
  for (size_t g = 0; g < ended_.size(); ++g) {
    const bool last = g + 1 == ended_.size();
    ObjectCloud& model = ended_[g].cloud;
    if (last && config_.keep_output_fused && config_.repair) result.output_fused = model;
    const std::string path =
        last ? config_.output_path
             : GraspModelPath(config_.output_path, model.grasp_id, ++times_seen[model.grasp_id]);
    result.grasps.push_back(Deliver(&model, ended_[g].seen, path,
                                    last ? DeliveredModel::kOutput : DeliveredModel::kEarlierGrasp));
    if (result.grasps.back().step != DeliveryStep::kDelivered) {
      result.end = ReplayEnd::kDeliveryFailed;
      return result;
    }
  }
  result.output = std::move(ended_.back().cloud);
  if (config_.collision_mesh) MakeCollisionMesh(&result);
  return result;
}

void ReplaySession::MakeCollisionMesh(ReplayResult* result) {
  const auto t_start = Clock::now();
  try {
    result->collision_mesh = mesh::BuildPlannerMesh(result->output, *config_.collision_mesh);
  } catch (const std::exception& e) {
    result->mesh_error = ErrorText(e);
    return;
  }
  result->mesh_ms = Ms(Clock::now() - t_start);
  if (!config_.publish) return;
  const ObjectCloud& cloud = result->output;
  const mesh::PlannerMesh& m = *result->collision_mesh;
  io::CollisionMeshMessage message;
  message.utime = cloud.utime;
  message.seq = cloud.seq;
  message.grasp_id = cloud.grasp_id;
  message.frame_name = cloud.frame_name;
  message.T_C_G = cloud.T_C_G;
  message.mesh = m.mesh;
  message.kind = m.kind;
  message.watertight = m.watertight;
  message.deviation_m = m.outside.max_m;
  if (!publisher_) publisher_ = std::make_unique<LcmPublisher>(config_.lcm_url);
  result->mesh_published = publisher_->PublishCollisionMesh(config_.log.channels.collision_mesh, message);
}

GraspDelivery ReplaySession::Deliver(ObjectCloud* model, const evidence::VisibilityRecord& seen,
                                     const std::string& path, DeliveredModel which) {
  GraspDelivery d;
  d.model = which;
  d.grasp_id = model->grasp_id;
  d.path = path;
  d.fused_points = model->size();
  const auto t_start = Clock::now();
  if (config_.repair) {
    try {
      d.repair = RepairObjectCloud(config_.repair_config, model, config_.repair_evidence ? &seen : nullptr);
    } catch (const std::exception& e) {  // *model is left as fused
      d.repair_error = ErrorText(e);
      if (which == DeliveredModel::kOutput) {
        d.step = DeliveryStep::kRepairFailed;
        return d;
      }
    }
  }
  const auto t_repaired = Clock::now();
  d.repair_ms = Ms(t_repaired - t_start);
  try {
    if (which == DeliveredModel::kEarlierGrasp) io::CheckOutputFile(path, config_.overwrite);
    io::WriteCloudFile(path, *model, io::ReplaceIf(config_.overwrite));
  } catch (const std::exception& e) {
    d.step = DeliveryStep::kWriteFailed;
    d.write_error = ErrorText(e);
    return d;
  }
  const auto t_written = Clock::now();
  d.write_ms = Ms(t_written - t_repaired);
  d.points = model->size();
  if (config_.publish) {
    if (!publisher_) publisher_ = std::make_unique<LcmPublisher>(config_.lcm_url);
    publisher_->PublishCloud(config_.log.channels.object_cloud, *model);
  }
  d.publish_ms = Ms(Clock::now() - t_written);
  return d;
}

}  // namespace graspfill::rt
