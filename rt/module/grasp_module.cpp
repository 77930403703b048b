// SPDX-License-Identifier: BSD-3-Clause
#include "module/grasp_module.hpp"

#include <stdexcept>
#include <utility>

namespace graspfill::rt {

namespace {
// A frame or two waits for its pose normally; more is worth a reason.
constexpr int64_t kStallTextAfterFrames = 3;
}  // namespace

GraspModule::GraspModule(const GraspModuleConfig& config, claw::ClawModel claw, CloudCallback on_cloud)
    : config_(config),
      on_cloud_(std::move(on_cloud)),
      sequencer_(config.pipeline, std::move(claw), config.grasps,
                 [this](const ObjectCloud& cloud, const evidence::VisibilityRecord& seen) {
                   // A grasp's final model (once per grasp: the copy is fine).
                   ++clouds_out_;
                   if (!on_cloud_) return;
                   ObjectCloud stamped = cloud;
                   StampLatency(&stamped, std::nullopt);
                   on_cloud_(stamped, seen);
                 }) {
  if (config.frame_queue_capacity < 1 || config.state_queue_capacity < 1 ||
      config.extract_every_n_frames < 0) {
    throw std::invalid_argument(
        "GraspModuleConfig: queue capacities must be >= 1, "
        "extract_every_n_frames >= 0");
  }
  frames_.resize(static_cast<size_t>(config.frame_queue_capacity));
  frame_arrival_.resize(frames_.size());
  states_.resize(static_cast<size_t>(config.state_queue_capacity));
  worker_ = std::thread(&GraspModule::WorkerLoop, this);
}

GraspModule::~GraspModule() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_worker_.notify_all();
  worker_.join();
}

void GraspModule::PushDepthFrame(const DepthFrame& frame) {
  const Clock::time_point arrival = Clock::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++status_.frames_in;
    if (frames_count_ == frames_.size()) {
      frames_head_ = (frames_head_ + 1) % frames_.size();
      --frames_count_;
      ++status_.frames_dropped;
    }
    const size_t at = (frames_head_ + frames_count_) % frames_.size();
    frame_arrival_[at] = arrival;
    DepthFrame& slot = frames_[at];
    slot.utime = frame.utime;
    slot.intrinsics = frame.intrinsics;
    slot.depth_m.assign(frame.depth_m.begin(), frame.depth_m.end());  // reuses capacity
    ++frames_count_;
  }
  wake_worker_.notify_one();
}

void GraspModule::PushGripperState(const GripperState& state) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (states_count_ == states_.size()) {
      states_head_ = (states_head_ + 1) % states_.size();
      --states_count_;
      ++status_.states_dropped;
    }
    states_[(states_head_ + states_count_) % states_.size()] = state;
    ++states_count_;
  }
  wake_worker_.notify_one();
}

bool GraspModule::PublishIfDue() {
  // A frame pends until the state after it arrives, so it is fused by
  // AddGripperState as often as by AddDepthFrame, and one call can fuse
  // several: a cloud whenever the count crosses a multiple of n.
  const int n = config_.extract_every_n_frames;
  const int64_t integrated = sequencer_.stats().frames_integrated;
  if (n <= 0 || integrated / n <= integrated_at_last_cloud_ / n) return false;
  integrated_at_last_cloud_ = integrated;
  const Clock::time_point start = Clock::now();
  ObjectCloud cloud = sequencer_.ExtractCloud();
  StampLatency(&cloud, start);
  if (on_cloud_) on_cloud_(cloud, sequencer_.pipeline().visibility());
  return true;
}

void GraspModule::StampLatency(ObjectCloud* cloud, std::optional<Clock::time_point> extract_start) const {
  const auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const Clock::time_point now = Clock::now();
  for (const TakenFrame& taken : taken_) {
    if (taken.utime != cloud->utime || taken.arrival == Clock::time_point{}) continue;
    cloud->timings.push_back({"latency_queue_wait", taken.queue_wait_ms});
    if (extract_start) cloud->timings.push_back({"latency_extract", ms(now - *extract_start)});
    cloud->timings.push_back({"latency_frame_to_cloud", ms(now - taken.arrival)});
    cloud->newest_frame_arrival = taken.arrival;
    return;
  }
}

void GraspModule::WorkerLoop() {
  DepthFrame frame;  // the worker's own copies, reused
  GripperState state;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_worker_.wait(lock,
                      [&] { return stop_ || frames_count_ > 0 || states_count_ > 0 || finish_requested_; });
    if (stop_) return;
    busy_ = true;
    // States first: a frame's bracketing state may have arrived with it.
    // But a state that ends the grasp waits for the frames taken before it.
    while (states_count_ > 0) {
      const GripperState& next = states_[states_head_];
      if (frames_count_ > 0 && sequencer_.EndsGrasp(next) && frames_[frames_head_].utime < next.utime) {
        break;
      }
      state = next;
      states_head_ = (states_head_ + 1) % states_.size();
      --states_count_;
      lock.unlock();
      sequencer_.AddGripperState(state);
      const bool published = PublishIfDue();
      lock.lock();
      status_.clouds_published += published;
    }
    if (frames_count_ > 0) {
      std::swap(frame.depth_m, frames_[frames_head_].depth_m);  // no copy
      frame.utime = frames_[frames_head_].utime;
      frame.intrinsics = frames_[frames_head_].intrinsics;
      TakenFrame& taken = taken_[taken_next_++ % taken_.size()];
      taken.utime = frame.utime;
      taken.arrival = frame_arrival_[frames_head_];
      taken.queue_wait_ms = std::chrono::duration<double, std::milli>(Clock::now() - taken.arrival).count();
      frames_head_ = (frames_head_ + 1) % frames_.size();
      --frames_count_;
      lock.unlock();
      sequencer_.AddDepthFrame(frame);
      const bool published = PublishIfDue();
      lock.lock();
      status_.clouds_published += published;
    }
    UpdateStatusLocked();
    if (finish_requested_ && frames_count_ == 0 && states_count_ == 0) {
      lock.unlock();
      ObjectCloud cloud = sequencer_.Finish();
      lock.lock();
      finished_cloud_ = std::move(cloud);
      UpdateStatusLocked();
      finish_requested_ = false;
      finished_ = true;
    }
    busy_ = false;
    idle_.notify_all();
  }
}

ObjectCloud GraspModule::Finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  finished_ = false;
  finish_requested_ = true;
  wake_worker_.notify_one();
  idle_.wait(lock, [&] { return finished_; });
  return std::move(finished_cloud_);
}

void GraspModule::UpdateStatusLocked() {
  status_.clouds_published += clouds_out_;
  clouds_out_ = 0;
  status_.pipeline = sequencer_.stats();
  status_.session = sequencer_.counters();
  // Text only once frames go unfused (no allocation while fusion runs).
  if (status_.session.frames_since_fused >= kStallTextAfterFrames) {
    status_.stall_reason = sequencer_.StallReason();
  } else {
    status_.stall_reason.clear();
  }
}

GraspModuleStatus GraspModule::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

}  // namespace graspfill::rt
