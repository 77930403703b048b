// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/session_recorder.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <utility>

#include "sinks/lcm_log_writer.hpp"

namespace graspfill::rt {
namespace {

constexpr int64_t kMinQueueBytes = int64_t{1} << 20;

// Bytes the buffers of `e` hold (their capacity, not their size).
int64_t BufferBytes(const SourceEvent& e) {
  return static_cast<int64_t>(e.depth.depth_m.capacity() * sizeof(float) +
                              e.gripper.joint_values.capacity() * sizeof(double));
}

}  // namespace

SessionRecorder::SessionRecorder(const Config& config, const io::SessionDescription& session)
    : config_(config), session_(session) {
  if (config.queue_capacity < 1) {
    throw std::invalid_argument("SessionRecorder: queue_capacity must be >= 1");
  }
  if (config.queue_bytes < kMinQueueBytes) {
    throw std::invalid_argument("SessionRecorder: queue_bytes must be >= 1 MiB");
  }
  if (config.sync_period_ms < 0) {
    throw std::invalid_argument("SessionRecorder: sync_period_ms must be >= 0");
  }
  io::EncodeSessionDescription(session_);  // a bad description fails now, not in the thread
  writer_ = std::make_unique<LcmLogWriter>(
      config.path, LcmLogWriter::Options{config.overwrite, LcmLogWriter::Mode::kInPlace});
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
  if (!failure_.empty() || count_ == slots_.size()) {
    ++dropped_;
    return nullptr;
  }
  return &slots_[(head_ + count_) % slots_.size()];
}

void SessionRecorder::ReleaseBuffers(SourceEvent* slot) {
  std::vector<float>().swap(slot->depth.depth_m);
  std::vector<double>().swap(slot->gripper.joint_values);
}

bool SessionRecorder::MakeRoom(size_t slot, size_t depth_values, size_t joint_values) {
  SourceEvent& target = slots_[slot];
  const size_t n = slots_.size();
  // What the slots hold once `target` holds the event.
  auto after = [&] {
    const size_t depth = std::max(target.depth.depth_m.capacity(), depth_values);
    const size_t joints = std::max(target.gripper.joint_values.capacity(), joint_values);
    return slot_bytes_ - BufferBytes(target) +
           static_cast<int64_t>(depth * sizeof(float) + joints * sizeof(double));
  };
  if (after() <= config_.queue_bytes) return true;
  // A free slot's buffer that is large enough (slots at ring offsets past
  // count_ hold no event): reused, nothing allocated.
  if (target.depth.depth_m.capacity() < depth_values) {
    for (size_t k = count_ + 1; k < n; ++k) {
      SourceEvent& free = slots_[(head_ + k) % n];
      if (free.depth.depth_m.capacity() >= depth_values) {
        std::swap(free.depth.depth_m, target.depth.depth_m);  // the slots' sum unchanged
        break;
      }
    }
    if (after() <= config_.queue_bytes) return true;
  }
  // The free slots give their buffers back, and so does `target` where
  // they are too small (not to hold old and new at once).
  for (size_t k = count_ + 1; k < n; ++k) {
    SourceEvent& free = slots_[(head_ + k) % n];
    slot_bytes_ -= BufferBytes(free);
    ReleaseBuffers(&free);
  }
  if (target.depth.depth_m.capacity() < depth_values ||
      target.gripper.joint_values.capacity() < joint_values) {
    slot_bytes_ -= BufferBytes(target);
    ReleaseBuffers(&target);
  }
  return after() <= config_.queue_bytes || count_ == 0;  // one event always fits
}

void SessionRecorder::RecordDepth(const DepthFrame& frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    SourceEvent* slot = Reserve();
    if (slot == nullptr) return;
    const size_t index = (head_ + count_) % slots_.size();
    if (!MakeRoom(index, frame.depth_m.size(), 0)) {
      ++dropped_;
      return;
    }
    slot_bytes_ -= BufferBytes(*slot);
    slot->kind = SourceEvent::Kind::kDepth;
    slot->depth.utime = frame.utime;
    slot->depth.intrinsics = frame.intrinsics;
    slot->depth.depth_m.assign(frame.depth_m.begin(), frame.depth_m.end());  // reuses capacity
    slot_bytes_ += BufferBytes(*slot);
    slot_bytes_peak_ = std::max(slot_bytes_peak_, slot_bytes_);
    ++count_;
  }
  wake_writer_.notify_one();
}

void SessionRecorder::RecordGripperState(const GripperState& state) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    SourceEvent* slot = Reserve();
    if (slot == nullptr) return;
    const size_t index = (head_ + count_) % slots_.size();
    if (!MakeRoom(index, 0, state.joint_values.size())) {
      ++dropped_;
      return;
    }
    slot_bytes_ -= BufferBytes(*slot);
    slot->kind = SourceEvent::Kind::kGripperState;
    slot->gripper.utime = state.utime;
    slot->gripper.T_C_G = state.T_C_G;
    slot->gripper.opening_m = state.opening_m;
    slot->gripper.joint_values.assign(state.joint_values.begin(), state.joint_values.end());
    slot->gripper.grasp_id = state.grasp_id;
    slot_bytes_ += BufferBytes(*slot);
    slot_bytes_peak_ = std::max(slot_bytes_peak_, slot_bytes_);
    ++count_;
  }
  wake_writer_.notify_one();
}

void SessionRecorder::Record(const SourceEvent& event) {
  if (event.kind == SourceEvent::Kind::kDepth)
    RecordDepth(event.depth);
  else if (event.kind == SourceEvent::Kind::kGripperState)
    RecordGripperState(event.gripper);
}

void SessionRecorder::StopAfterFailure(const std::string& why) {
  if (!failure_.empty()) return;
  failure_ = why;
  dropped_ += static_cast<int64_t>(count_);  // what waited is not written
  count_ = 0;
  for (SourceEvent& slot : slots_) ReleaseBuffers(&slot);
  slot_bytes_ = 0;
  std::fprintf(stderr,
               "graspfill: recording stopped after %lld events: %s; the log keeps them "
               "(graspfill replay and lcm-logplayer play it); the session goes on\n",
               static_cast<long long>(written_), why.c_str());
}

void SessionRecorder::WriterLoop() {
  using Clock = std::chrono::steady_clock;
  const auto sync_period = std::chrono::milliseconds(config_.sync_period_ms);
  SourceEvent event;  // the writer's copy, buffers swapped with a slot
  bool session_written = false;
  bool unsynced = false;  // events written since the last fdatasync
  Clock::time_point last_sync = Clock::now();
  // Writes (lock not held); "" or why it failed.
  auto write = [&]() -> std::string {
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
        writer_->Write(config_.channels.gripper_state, utime, io::EncodeGripperState(event.gripper));
      }
      unsynced = true;
      if (Clock::now() - last_sync >= sync_period) {
        writer_->Flush();
        unsynced = false;
        last_sync = Clock::now();
      }
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    const auto ready = [&] { return stop_ || count_ > 0; };
    if (unsynced && failure_.empty()) {
      wake_writer_.wait_until(lock, last_sync + sync_period, ready);
    } else {
      wake_writer_.wait(lock, ready);
    }
    if (count_ == 0) {
      if (stop_) return;  // Close() flushes and closes the log
      if (!unsynced || !failure_.empty() || Clock::now() - last_sync < sync_period) continue;
      // Idle past the period with events not yet durable.
      lock.unlock();
      std::string failure;
      try {
        writer_->Flush();
      } catch (const std::exception& e) {
        failure = e.what();
      }
      unsynced = false;
      last_sync = Clock::now();
      lock.lock();
      if (!failure.empty()) StopAfterFailure(failure);
      continue;
    }
    SourceEvent& slot = slots_[head_];
    slot_bytes_ -= BufferBytes(slot);
    std::swap(event.depth.depth_m, slot.depth.depth_m);
    std::swap(event.gripper.joint_values, slot.gripper.joint_values);
    // The slot now holds the writer's previous buffers: given back where
    // they would take the ring over its budget.
    if (slot_bytes_ + BufferBytes(slot) > config_.queue_bytes) ReleaseBuffers(&slot);
    slot_bytes_ += BufferBytes(slot);
    event.kind = slot.kind;
    event.depth.utime = slot.depth.utime;
    event.depth.intrinsics = slot.depth.intrinsics;
    event.gripper.utime = slot.gripper.utime;
    event.gripper.T_C_G = slot.gripper.T_C_G;
    event.gripper.opening_m = slot.gripper.opening_m;
    event.gripper.grasp_id = slot.gripper.grasp_id;
    head_ = (head_ + 1) % slots_.size();
    --count_;
    lock.unlock();
    const std::string failure = write();
    lock.lock();
    if (failure.empty()) {
      ++written_;
    } else {
      ++dropped_;
      StopAfterFailure(failure);
    }
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
  if (!failure_.empty()) return;  // stopped: the failed write closed the log
  if (written_ == 0) {
    // Nothing received: still a valid log that says what the session was.
    writer_->Write(config_.channels.session, session_.utime, io::EncodeSessionDescription(session_));
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

std::string SessionRecorder::failure() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failure_;
}

int64_t SessionRecorder::queue_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return slot_bytes_;
}

int64_t SessionRecorder::queue_bytes_peak() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return slot_bytes_peak_;
}

}  // namespace graspfill::rt
