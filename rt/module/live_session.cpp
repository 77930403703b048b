// SPDX-License-Identifier: BSD-3-Clause
#include "module/live_session.hpp"

#include "module/process_memory.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>
#include <utility>

namespace graspfill::rt {

namespace {

const char* StateName(io::ModuleState state) {
  switch (state) {
    case io::ModuleState::kWaiting:
      return "waiting";
    case io::ModuleState::kFusing:
      return "fusing";
    case io::ModuleState::kRepairing:
      return "repairing";
    case io::ModuleState::kStalled:
      return "stalled";
    case io::ModuleState::kError:
      return "error";
  }
  return "error";
}

}  // namespace

LiveSession::LiveSession(const LiveSessionConfig& config) : config_(config), publisher_(config.lcm_url) {
  if (config.heap_reserve_mb < 0) throw std::invalid_argument("LiveSessionConfig: heap_reserve_mb < 0");
  if (config.heap_reserve_mb > 0 && !ReserveHeap(static_cast<size_t>(config.heap_reserve_mb))) {
    std::fprintf(stderr,
                 "graspfill: the heap could not be readied for the real-time loop "
                 "(%d MB reserve); continuing with the allocator's defaults\n",
                 config.heap_reserve_mb);
  }
  LcmBusSubscriber::Config bus;
  bus.url = config.lcm_url;
  bus.channels = config.channels;
  bus.overrides = config.overrides;
  bus.max_depth_pixels = config.max_depth_pixels;
  if (!config_.on_notice) {
    config_.on_notice = [](const std::string& text) {
      std::fprintf(stderr, "graspfill: %s\n", text.c_str());
    };
  }
  // A model too large for a default subscriber: said once, while it goes out.
  publisher_.set_on_warning([this](const std::string& text) { config_.on_notice("warning: " + text); });
  const std::string rejected = "session description on " + config.channels.session + " rejected (";
  const std::string kept =
      "; the session keeps its claw and config (further ones of this kind "
      "are only counted in the status)";
  if (config.build_session_claw) {
    SessionClawChecker::Callbacks callbacks;
    callbacks.on_unloadable = [this, rejected, kept](const io::SessionDescription&, const std::string& why) {
      ++claws_unloadable_;
      NoticeOnce(io::MessageError::kClawUnloadable,
                 rejected + io::MessageErrorName(io::MessageError::kClawUnloadable) + "): " + why + kept);
    };
    callbacks.on_other_claw = config.on_other_claw;
    claw_checker_ = std::make_unique<SessionClawChecker>(config.build_session_claw, config.same_claw,
                                                         std::move(callbacks));
  }
  subscriber_ = std::make_unique<LcmBusSubscriber>(
      bus, [this](const GripperState& s) { OnGripperState(s); },
      config.depth_from_bus ? LcmBusSubscriber::DepthCallback([this](const DepthFrame& f) { OnDepth(f); })
                            : LcmBusSubscriber::DepthCallback(),
      [this](const io::SessionDescription& session) {
        if (claw_checker_) claw_checker_->Submit(session);  // never waits for the build
      },
      [this, rejected, kept](io::MessageError reason, const std::string& why) {
        NoticeOnce(reason, rejected + io::MessageErrorName(reason) + "): " + why + kept);
      });
}

LiveSession::~LiveSession() {
  subscriber_.reset();    // no more events from the bus's thread
  claw_checker_.reset();  // nor from the checker's (after the build under way)
}

void LiveSession::NoticeOnce(io::MessageError reason, const std::string& text) {
  if (noticed_[static_cast<size_t>(reason)].exchange(true)) return;
  config_.on_notice(text);
}

bool LiveSession::WaitSessionChecks(std::chrono::milliseconds timeout) const {
  return !claw_checker_ || claw_checker_->WaitIdle(timeout);
}

std::optional<DescribedClaw> LiveSession::WaitForFirstEvent() {
  const auto start = std::chrono::steady_clock::now();
  const SessionLoopLimits& limits = config_.limits;
  const auto first_built = [this]() -> std::optional<DescribedClaw> {
    return claw_checker_ ? claw_checker_->FirstBuilt() : std::nullopt;
  };
  for (;;) {
    if (std::optional<DescribedClaw> built = first_built()) return built;
    bool depth_came = false;
    {
      std::lock_guard<std::mutex> lock(intake_mutex_);
      depth_came = !early_frames_.empty();
    }
    // A description received before the frame is in the checker already
    // (the bus's thread hands them over in order): its claw is waited for.
    if (depth_came && (!claw_checker_ || claw_checker_->Idle())) return first_built();
    if (limits.interrupted != nullptr && limits.interrupted->load()) break;
    if (limits.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limits.duration_s) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return first_built();
}

void LiveSession::PublishCloud(const ObjectCloud& cloud) {
  last_points_out_ = cloud.size();
  {
    std::lock_guard<std::mutex> lock(publisher_mutex_);
    publisher_.PublishCloud(config_.channels.object_cloud, cloud);
  }
  // The age of the cloud's newest frame when it went out (when known).
  const bool aged = cloud.newest_frame_arrival != std::chrono::steady_clock::time_point{};
  const double age_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cloud.newest_frame_arrival)
          .count();
  std::lock_guard<std::mutex> lock(latency_mutex_);
  ++clouds_published_;
  if (aged) latency_ms_.Add(age_ms);
}

void LiveSession::Begin(claw::ClawModel claw, const io::SessionDescription& description,
                        const std::optional<PipelineConfig>& pipeline) {
  if (pipeline) config_.module.pipeline = *pipeline;
  if (claw_checker_) claw_checker_->SetClawInUse(claw, description);
  if (config_.repair) {
    repair_stage_ = std::make_unique<RepairStage>(
        config_.repair_config, [this](const ObjectCloud& cloud) { PublishCloud(cloud); },
        config_.repair_options);
  }
  if (!config_.record.path.empty()) {
    config_.record.channels = config_.channels;
    recorder_ = std::make_unique<SessionRecorder>(config_.record, description);
  }
  module_ = std::make_unique<GraspModule>(
      config_.module, std::move(claw),
      [this](const ObjectCloud& cloud, const evidence::VisibilityRecord& seen) {
        if (repair_stage_) {
          repair_stage_->Submit(cloud, config_.repair_evidence ? &seen : nullptr);  // never waits
        } else
          PublishCloud(cloud);
      });
  SessionLoopLimits limits = config_.limits;
  limits.on_tick = [this] {
    if (on_tick_) on_tick_();
    PublishStatus();
  };
  std::lock_guard<std::mutex> lock(intake_mutex_);
  loop_ = std::make_unique<SessionLoop>(limits);  // OnDepth reads it under the lock
  for (const GripperState& s : early_states_) {
    if (recorder_) recorder_->RecordGripperState(s);
    module_->PushGripperState(s);
  }
  for (const DepthFrame& f : early_frames_) {
    if (recorder_) recorder_->RecordDepth(f);
    module_->PushDepthFrame(f);
  }
  early_states_.clear();
  early_frames_.clear();
  begun_ = true;
}

void LiveSession::OnGripperState(const GripperState& state) {
  std::lock_guard<std::mutex> lock(intake_mutex_);
  if (begun_) {
    if (recorder_) recorder_->RecordGripperState(state);
    module_->PushGripperState(state);
    return;
  }
  if (early_states_.size() == kMaxEarlyStates) early_states_.pop_front();
  early_states_.push_back(state);
}

void LiveSession::OnDepth(const DepthFrame& frame) {
  std::lock_guard<std::mutex> lock(intake_mutex_);
  if (begun_) {
    if (recorder_) recorder_->RecordDepth(frame);
    module_->PushDepthFrame(frame);
    loop_->NoteDepthFrame();  // the idle rule
  } else {
    if (early_frames_.size() == kMaxEarlyFrames) early_frames_.pop_front();
    early_frames_.push_back(frame);
  }
}

bool LiveSession::OnEvent(const SourceEvent& event) {
  // Run's source gives depth (a camera); the bus gives the rest.
  if (event.kind == SourceEvent::Kind::kDepth)
    OnDepth(event.depth);
  else if (event.kind == SourceEvent::Kind::kGripperState)
    OnGripperState(event.gripper);
  return true;
}

bool LiveSession::OnBadEvent(const SourceEvent&) {
  ++source_errors_;  // e.g. a camera timeout: counted, the session goes on
  return true;
}

io::ModuleStatus LiveSession::Status() const {
  io::ModuleStatus status;
  const GraspModuleStatus s = module_ ? module_->status() : GraspModuleStatus{};
  const SessionCounters& c = s.session;
  status.utime = c.last_frame_utime;
  status.frames_in = s.frames_in;
  status.frames_used = s.pipeline.frames_integrated;
  status.frames_skipped_no_pose = s.pipeline.frames_skipped_no_pose;
  status.frames_skipped_clock_jump = c.skipped_clock_jump;
  status.frames_bad = s.pipeline.frames_bad + source_errors_;
  status.frames_skipped_refine = s.pipeline.frames_skipped_refine + s.pipeline.frames_skipped_tracking;
  status.frames_skipped = status.frames_skipped_no_pose + status.frames_skipped_clock_jump +
                          s.pipeline.frames_bad + status.frames_skipped_refine + c.frames_released;
  status.frames_dropped = s.frames_dropped + s.pipeline.frames_dropped;
  status.frames_skipped_by_reason = s.pipeline.skipped;
  status.frames_skipped_by_reason.Count(FrameSkipReason::kBadFrame, source_errors_);
  status.last_frame_ms = s.pipeline.crop.last_ms + s.pipeline.mask.last_ms + s.pipeline.integrate.last_ms;
  if (subscriber_) status.bad_messages = subscriber_->bad_messages();
  status.bad_messages.by_reason[static_cast<size_t>(io::MessageError::kClawUnloadable)] += claws_unloadable_;
  status.decode_errors = status.bad_messages.total();
  status.clock_jumps = c.clock_jumps;
  status.grasp_id = c.grasp_id;
  status.grasps_completed = c.grasps_completed;
  int64_t finals_pending = 0;
  if (repair_stage_) {
    const RepairStageStatus r = repair_stage_->status();
    status.repairs_done = r.repaired;
    status.repairs_superseded = r.superseded;
    status.repairs_failed = r.failed;
    finals_pending = r.finals_pending;
    status.repair_updates = r.updates;
    status.repairs_full = r.full_published + r.rebases;
    status.update_ms_p50 = r.update_ms.p50;
    status.update_ms_p99 = r.update_ms.p99;
    status.full_repair_ms_p50 = r.full_ms.p50;
    status.full_repair_ms_p99 = r.full_ms.p99;
  }
  {
    std::lock_guard<std::mutex> lock(latency_mutex_);
    const Percentiles latency = latency_ms_.Summary();
    status.latency_ms_p50 = latency.p50;
    status.latency_ms_p95 = latency.p95;
    status.latency_ms_p99 = latency.p99;
    status.latency_ms_max = latency.max;
    status.clouds_published = clouds_published_;
  }
  status.rss_mb = ResidentMemoryMb();
  if (finals_pending > 0) {
    status.state_code = io::ModuleState::kRepairing;
  } else if (s.frames_in == 0 || !c.holding) {
    status.state_code = io::ModuleState::kWaiting;
  } else if (c.frames_since_fused >= config_.stall_after_frames) {
    status.state_code = io::ModuleState::kStalled;
    status.state_detail = s.stall_reason;
  } else {
    status.state_code = io::ModuleState::kFusing;
  }
  if (recorder_) {
    // A recording that stopped (a full disk) is said while fusing goes on.
    const std::string failure = recorder_->failure();
    if (!failure.empty()) {
      status.state_detail += (status.state_detail.empty() ? "" : "; ") + ("recording stopped: " + failure);
    }
  }
  status.state = StateName(status.state_code);
  if (!status.state_detail.empty()) status.state += ": " + status.state_detail;
  return status;
}

void LiveSession::PublishStatus() {
  last_status_ = Status();
  std::lock_guard<std::mutex> lock(publisher_mutex_);
  publisher_.PublishStatus(config_.channels.status, last_status_);
}

LiveSessionSummary LiveSession::Run(FrameSource* source, std::function<void()> on_tick) {
  if (!module_) throw std::logic_error("LiveSession::Run before Begin");
  on_tick_ = std::move(on_tick);
  loop_->Run(source, this);
  // A claw check under way (a description that came at the end) has a
  // moment to tell its verdict; a build that takes longer is not waited for
  // here (the destructor joins it).
  WaitSessionChecks(std::chrono::milliseconds(1000));

  LiveSessionSummary summary;
  const ObjectCloud fused = module_->Finish();
  summary.final_points = fused.size();
  if (repair_stage_) {
    repair_stage_->Drain();  // the last cloud out repaired, not dropped
    summary.final_points = last_points_out_;
    summary.repair = repair_stage_->status();
  }
  PublishStatus();  // the final counters
  summary.module = module_->status();
  summary.states_received = subscriber_->states_received();
  summary.source_errors = source_errors_;
  summary.status = last_status_;
  {
    std::lock_guard<std::mutex> lock(latency_mutex_);
    summary.latency_ms = latency_ms_.Summary();
    summary.clouds_published = clouds_published_;
  }
  if (recorder_) {
    // Stop feeding the recorder before closing it.
    {
      std::lock_guard<std::mutex> lock(intake_mutex_);
      begun_ = false;
    }
    summary.records_written = recorder_->events_written();
    recorder_->Close();  // throws naming the path if closing the log failed
    summary.records_written = recorder_->events_written();
    summary.records_dropped = recorder_->events_dropped();
    summary.record_failure = recorder_->failure();
  }
  return summary;
}

}  // namespace graspfill::rt
