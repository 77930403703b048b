#include "sinks/session_recorder.hpp"

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <utility>

#include "sinks/lcm_log_writer.hpp"

namespace graspfill::rt {

SessionRecorder::SessionRecorder(const Config& config, const io::SessionDescription& session)
    : config_(config), session_(session) {
  if (config.queue_capacity < 1) {
    throw std::invalid_argument("SessionRecorder: queue_capacity must be >= 1");
  }
  io::EncodeSessionDescription(session_);  // a bad description fails now, not in the thread
  writer_ = std::make_unique<LcmLogWriter>(config.path, config.overwrite);
  slots_.resize(static_cast<size_t>(config.queue_capacity));
  thread_ = std::thread(&SessionRecorder::WriterLoop, this);
}

SessionRecorder::~SessionRecorder() {
  try {
    Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill: recording: %s\n", e.what());
  }
}

SourceEvent* SessionRecorder::Reserve() {
  if (closed_) return nullptr;
  if (count_ == slots_.size()) {
    ++dropped_;
    return nullptr;
  }
  return &slots_[(head_ + count_) % slots_.size()];
}

void SessionRecorder::RecordDepth(const DepthFrame& frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    SourceEvent* slot = Reserve();
    if (slot == nullptr) return;
    slot->kind = SourceEvent::Kind::kDepth;
    slot->depth.utime = frame.utime;
    slot->depth.intrinsics = frame.intrinsics;
    slot->depth.depth_m.assign(frame.depth_m.begin(), frame.depth_m.end());  // reuses capacity
    ++count_;
  }
  wake_writer_.notify_one();
}

void SessionRecorder::RecordGripperState(const GripperState& state) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    SourceEvent* slot = Reserve();
    if (slot == nullptr) return;
    slot->kind = SourceEvent::Kind::kGripperState;
    slot->gripper.utime = state.utime;
    slot->gripper.T_C_G = state.T_C_G;
    slot->gripper.opening_m = state.opening_m;
    slot->gripper.joint_values.assign(state.joint_values.begin(), state.joint_values.end());
    slot->gripper.grasp_id = state.grasp_id;
    ++count_;
  }
  wake_writer_.notify_one();
}

void SessionRecorder::Record(const SourceEvent& event) {
  if (event.kind == SourceEvent::Kind::kDepth) RecordDepth(event.depth);
  else if (event.kind == SourceEvent::Kind::kGripperState) RecordGripperState(event.gripper);
}

void SessionRecorder::WriterLoop() {
  SourceEvent event;  // the writer's copy, swapped with a slot
  bool session_written = false;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_writer_.wait(lock, [&] { return stop_ || count_ > 0; });
    if (count_ == 0) return;  // stop_ and nothing left
    std::swap(event.depth.depth_m, slots_[head_].depth.depth_m);
    std::swap(event.gripper.joint_values, slots_[head_].gripper.joint_values);
    event.kind = slots_[head_].kind;
    event.depth.utime = slots_[head_].depth.utime;
    event.depth.intrinsics = slots_[head_].depth.intrinsics;
    event.gripper.utime = slots_[head_].gripper.utime;
    event.gripper.T_C_G = slots_[head_].gripper.T_C_G;
    event.gripper.opening_m = slots_[head_].gripper.opening_m;
    event.gripper.grasp_id = slots_[head_].gripper.grasp_id;
    head_ = (head_ + 1) % slots_.size();
    --count_;
    busy_ = true;
    const bool failed = !failure_.empty();
    lock.unlock();
    std::string failure;
    if (!failed) {
      try {
        const bool depth = event.kind == SourceEvent::Kind::kDepth;
        const int64_t utime = depth ? event.depth.utime : event.gripper.utime;
        if (!session_written) {
          session_.utime = utime;
          writer_->Write(config_.channels.session, utime, io::EncodeSessionDescription(session_));
          session_written = true;
        }
        if (depth) {
          writer_->Write(config_.channels.depth, utime,
                         io::EncodeDepthImage(event.depth, io::DepthEncoding::kZlib16, 0.001));
        } else {
          writer_->Write(config_.channels.gripper_state, utime,
                         io::EncodeGripperState(event.gripper));
        }
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    lock.lock();
    if (!failure.empty() && failure_.empty()) failure_ = failure;
    if (failed || !failure.empty()) ++dropped_;
    else ++written_;
    busy_ = false;
    idle_.notify_all();
  }
}

void SessionRecorder::Close() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (closed_) return;
    closed_ = true;
    stop_ = true;
  }
  wake_writer_.notify_all();
  thread_.join();
  if (!failure_.empty()) {
    writer_.reset();  // abandoned: the temporary file is removed
    throw std::runtime_error("recording '" + config_.path + "' failed: " + failure_);
  }
  if (written_ == 0) {
    // Nothing received: still a valid log that says what the session was.
    writer_->Write(config_.channels.session, session_.utime,
                   io::EncodeSessionDescription(session_));
  }
  writer_->Close();
}

int64_t SessionRecorder::events_written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

int64_t SessionRecorder::events_dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace graspfill::rt
