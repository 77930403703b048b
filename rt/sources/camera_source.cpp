// SPDX-License-Identifier: BSD-3-Clause
#include "sources/camera_source.hpp"

#include <utility>

#include "drivers/openni2_replay/graspfill_replay_properties.hpp"
#include "graspfill/io/lcm_log_reader.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill::rt {
namespace {

// The utime of the log's first depth image on `channel`, if it has one.
std::optional<int64_t> FirstDepthUtime(const std::string& path, const std::string& channel) {
  io::LcmLogReader reader(path);
  io::LogEvent event;
  DepthFrame frame;
  std::string error;
  while (reader.Next(&event) == io::LogReadResult::kEvent) {
    if (event.channel != channel) continue;
    if (io::DecodeDepthImage(event.data.data(), event.data.size(), &frame, &error)) {
      return frame.utime;
    }
  }
  return std::nullopt;
}

}  // namespace

CameraSource::CameraSource(const Config& config) : config_(config) {
  const std::string prefix = openni2_replay::kUriPrefix;
  if (config_.log.empty() && config_.device.uri.compare(0, prefix.size(), prefix) == 0) {
    config_.log = config_.device.uri.substr(prefix.size());
  }
  if (!config_.log.empty()) {
    LcmLogSource::Config log_config;
    log_config.path = config_.log;
    log_config.channels = config_.channels;
    // Depth comes through OpenNI2: the log's own depth images are skipped
    // undecoded (no channel is named "").
    log_config.channels.depth.clear();
    log_config.session_events = true;
    log_config.overrides = config_.overrides;
    log_ = std::make_unique<LcmLogSource>(log_config);  // throws on a bad file
    log_first_depth_utime_ = FirstDepthUtime(config_.log, config_.channels.depth);
    FillLog();
    if (log_pending_ && log_result_ == FrameResult::kOk && log_event_.kind == SourceEvent::Kind::kSession) {
      head_session_ = log_event_.session;
    }
  }
  device_ = std::make_unique<OpenNI2Source>(config_.device);
}

CameraSource::~CameraSource() = default;

bool CameraSource::FillCamera() {
  if (camera_pending_ || camera_ended_) return camera_pending_;
  if (frame_gate_ && device_->paced_by_reader()) frame_gate_();
  camera_result_ = device_->Next(&camera_event_);
  if (camera_result_ == FrameResult::kEndOfStream) {
    camera_ended_ = true;
    return false;
  }
  if (camera_result_ == FrameResult::kOk && log_) {
    if (!camera_offset_us_) {
      // A replay device's stamps are the log's already (offset 0); an .oni's
      // start at 0 and a camera's are its host's clock.
      camera_offset_us_ = device_->is_recording() && log_first_depth_utime_
                              ? *log_first_depth_utime_ - camera_event_.depth.utime
                              : 0;
    }
    camera_event_.depth.utime += *camera_offset_us_;
    if (!config_.device.intrinsics.any() &&
        !ApplyIntrinsicsOverride(intrinsics_override_, &camera_event_.depth, &camera_event_.error)) {
      camera_result_ = FrameResult::kBadFrame;
    }
  }
  camera_pending_ = true;
  return true;
}

bool CameraSource::FillLog() {
  if (!log_ || log_pending_ || log_ended_) return log_pending_;
  log_result_ = log_->Next(&log_event_);
  if (log_result_ == FrameResult::kEndOfStream) {
    log_ended_ = true;
    return false;
  }
  log_pending_ = true;
  return true;
}

FrameResult CameraSource::Next(SourceEvent* event) {
  if (!log_) {
    if (frame_gate_ && device_->paced_by_reader()) frame_gate_();
    return device_->Next(event);
  }
  bool take_log;
  if (head_session_ && !head_session_sent_) {
    head_session_sent_ = true;
    take_log = true;  // pending since the constructor
  } else {
    // The log first: a session read ahead applies to the frame after it.
    const bool have_log = FillLog();
    const bool have_camera = FillCamera();
    if (!have_log && !have_camera) return FrameResult::kEndOfStream;
    auto utime = [](const SourceEvent& e) {
      switch (e.kind) {
        case SourceEvent::Kind::kDepth:
          return e.depth.utime;
        case SourceEvent::Kind::kGripperState:
          return e.gripper.utime;
        case SourceEvent::Kind::kSession:
          return e.session.utime;
      }
      return int64_t{0};
    };
    take_log = have_log &&
               (!have_camera || log_result_ != FrameResult::kOk || utime(log_event_) <= utime(camera_event_));
  }
  if (take_log) {
    log_pending_ = false;
    std::swap(*event, log_event_);
    if (log_result_ == FrameResult::kOk && event->kind == SourceEvent::Kind::kSession) {
      intrinsics_override_ = event->session.intrinsics;
    }
    return log_result_;
  }
  camera_pending_ = false;
  std::swap(*event, camera_event_);
  return camera_result_;
}

}  // namespace graspfill::rt
