// SPDX-License-Identifier: BSD-3-Clause
// The live grasp-reconstruction module: a worker thread that owns the
// Pipeline (through a GraspSequencer: grasp after grasp, clock jumps), fed
// through bounded queues by the camera driver and the robot's state stream,
// and hands the object cloud to a callback (e.g. the repair stage) every few
// frames, and each grasp's final model (ObjectCloud::is_final) when the
// grasp ends.
//
// Latency: each cloud handed out carries its newest frame's arrival
// (ObjectCloud::newest_frame_arrival) and, in its timings, that frame's
// age: "latency_queue_wait" (arrival -> the worker took it),
// "latency_extract" and "latency_frame_to_cloud" (arrival -> extracted)
// [ms]; the repair stage and the publisher measure theirs from the arrival.
//
// Threads: Push* and the accessors are safe from any thread and never wait
// for the worker's processing (they take a short lock to copy the data into
// a preallocated slot). The cloud callback runs on the worker thread.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "graspfill/pipeline/pipeline.hpp"
#include "module/grasp_sequencer.hpp"

namespace graspfill::rt {

struct GraspModuleConfig {
  PipelineConfig pipeline;
  /// Depth frames waiting for the worker; when full the oldest is dropped
  /// (and counted): a live loop wants the freshest frames, not a backlog.
  int frame_queue_capacity{4};
  /// Gripper states waiting for the worker (100 Hz states, 30 Hz frames).
  int state_queue_capacity{64};
  /// Extract and publish the cloud after every this many integrated frames;
  /// 0 = only when ExtractNow() is called.
  int extract_every_n_frames{30};
  /// Grasp and clock-jump rules (grasp_sequencer.hpp).
  GraspSequencerConfig grasps;
};

struct GraspModuleStatus {
  int64_t frames_in{0};
  int64_t frames_dropped{0};  ///< queue overflow (worker too slow)
  int64_t states_dropped{0};
  PipelineStats pipeline;    ///< snapshot from the worker, summed over grasps
  SessionCounters session;   ///< grasps, clock jumps, skips by reason
  std::string stall_reason;  ///< why the last frames were not fused
  int64_t clouds_published{0};
};

class GraspModule {
 public:
  /// The cloud and what the camera saw so far (a snapshot: the record is
  /// cheap to copy and stays valid after the module resets). A grasp's
  /// final model has is_final set.
  using CloudCallback = std::function<void(const ObjectCloud&, const evidence::VisibilityRecord&)>;

  /// Starts the worker. Throws std::invalid_argument on a bad config.
  GraspModule(const GraspModuleConfig& config, claw::ClawModel claw, CloudCallback on_cloud);
  /// Drains nothing: stops the worker after the item it is processing.
  ~GraspModule();
  GraspModule(const GraspModule&) = delete;
  GraspModule& operator=(const GraspModule&) = delete;

  void PushDepthFrame(const DepthFrame& frame);
  void PushGripperState(const GripperState& state);

  /// Waits until every queued item is processed, flushes pending frames
  /// and returns the last grasp's final model (also handed to the callback;
  /// empty, and not handed, when that grasp fused nothing after an earlier
  /// grasp's model went out).
  ObjectCloud Finish();

  GraspModuleStatus status() const;

 private:
  void WorkerLoop();
  // Worker thread, lock not held: extracts and hands out a cloud when
  // another extract_every_n_frames frames have been fused; true if it did.
  bool PublishIfDue();
  // Worker: the newest frame's arrival and the latency timings of `cloud`
  // (see the file comment), with its extraction's when its start is given;
  // none when its newest frame is not known.
  void StampLatency(ObjectCloud* cloud,
                    std::optional<std::chrono::steady_clock::time_point> extract_start) const;
  // Worker, lock held: the status from the sequencer (not touched by
  // another thread while the worker holds the lock).
  void UpdateStatusLocked();

  const GraspModuleConfig config_;
  CloudCallback on_cloud_;
  int64_t clouds_out_{0};     // worker only: callbacks since the last merge
  GraspSequencer sequencer_;  // touched by the worker only

  mutable std::mutex mutex_;
  std::condition_variable wake_worker_;
  std::condition_variable idle_;
  using Clock = std::chrono::steady_clock;
  std::vector<DepthFrame> frames_;                // ring of reusable slots
  std::vector<Clock::time_point> frame_arrival_;  // beside frames_
  size_t frames_head_{0}, frames_count_{0};
  std::vector<GripperState> states_;  // ring
  size_t states_head_{0}, states_count_{0};
  int64_t integrated_at_last_cloud_{0};  // worker only
  struct TakenFrame {
    int64_t utime{0};
    Clock::time_point arrival;
    double queue_wait_ms{0.0};
  };
  // Worker only: the frames taken lately (more than the pipeline keeps
  // pending), to find a cloud's newest frame by its utime.
  std::array<TakenFrame, 32> taken_{};
  size_t taken_next_{0};
  bool busy_{false};
  bool stop_{false};
  bool finish_requested_{false};
  ObjectCloud finished_cloud_;
  bool finished_{false};
  GraspModuleStatus status_;
  std::thread worker_;  // last: starts after everything above exists
};

}  // namespace graspfill::rt
