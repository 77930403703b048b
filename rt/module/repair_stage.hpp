// SPDX-License-Identifier: BSD-3-Clause
// The live loop's hole repair, off the fusion thread: a repair takes
// 100-200 ms on a fused cloud while a depth frame must be fused within
// ~33 ms, so the repair gets a thread of its own, fed through a one-slot
// mailbox holding the latest cloud. A cloud still waiting when a newer one
// arrives is replaced (and counted as superseded): the planner wants the
// freshest model, not a backlog of stale ones. A grasp's final model
// (ObjectCloud::is_final) is never replaced: finals wait in a queue of
// their own, are repaired first, in order, and a cloud of the same grasp
// waiting in the mailbox when its final comes is superseded by it.
//
// Incremental (the default): each cloud is an update of the last full
// repair (the base, repair/incremental_repair.hpp: milliseconds). When the
// update says a full repair is due, the cloud goes to a second thread that
// repairs it in full at a lower priority than fusion (nice +10) and then
// becomes the new base; updates go on meanwhile with the old one. Until a
// grasp's first full repair has landed (60-1,000 ms) its clouds go out as
// fused, unrepaired (counted): a full repair never holds a cloud back.
// Finals are always repaired in full, in order. Off (`incremental =
// false`): every cloud is repaired in full on the stage's thread.
//
// Latency: before the callback, the stage adds to the cloud's timings
// "latency_repair_wait" (Submit -> taken), "latency_repair" (the update or
// the full repair) and, when the cloud came with its newest frame's
// arrival (ObjectCloud::newest_frame_arrival, kept on the repaired cloud),
// "latency_frame_to_repaired" (that arrival -> now) [ms].
//
// Threads: Submit and status() are safe from any thread and never wait for
// a repair (they take a short lock; Submit copies the cloud into a slot
// whose buffers are reused from cloud to cloud). The output callback runs
// on the stage's thread, once per repaired (or failed) cloud, in order.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "graspfill/repair/incremental_repair.hpp"
#include "graspfill/repair/repairer.hpp"
#include "graspfill/types.hpp"
#include "module/sample_window.hpp"

namespace graspfill::rt {

struct RepairStageOptions {
  /// Updates between full repairs (see the file comment); false: a full
  /// repair per cloud.
  bool incremental{true};
  repair::IncrementalConfig incremental_config;
};

struct RepairStageStatus {
  int64_t submitted{0};
  /// Repair ran to the end; its verdict ("repaired", "no holes found", ...)
  /// for the last one is in last_status.
  int64_t repaired{0};
  /// Replaced in the mailbox by a newer cloud before its repair started.
  int64_t superseded{0};
  /// Repair threw: the cloud was handed on unrepaired (reason on stderr
  /// and in last_status).
  int64_t failed{0};
  int64_t published{0};  ///< output callback calls that returned normally
  double last_repair_ms{0.0};
  size_t last_points_in{0};
  size_t last_points_out{0};
  std::string last_status;
  /// Final models waiting or being repaired now (status "repairing").
  int64_t finals_pending{0};
  /// Published as fused: no full repair of the grasp had landed yet
  /// (incremental only; not counted in `repaired`).
  int64_t unrepaired{0};
  /// Of `repaired`: incremental updates published, full repairs published
  /// (finals, or every cloud when not incremental).
  int64_t updates{0};
  int64_t full_published{0};
  /// Full repairs run in the background that became the base.
  int64_t rebases{0};
  std::string last_rebase_reason;  ///< why the last background repair ran
  /// Wall time of the updates and of every full repair (published or
  /// background) over the last 4096 of each [ms].
  Percentiles update_ms;
  Percentiles full_ms;
};

class RepairStage {
 public:
  using CloudCallback = std::function<void(const ObjectCloud&)>;

  /// Starts the thread. `config` is used as given (see
  /// GripperFrameRepairConfig for clouds in G). Throws
  /// std::invalid_argument on a bad config.
  RepairStage(const repair::RepairConfig& config, CloudCallback on_cloud,
              const RepairStageOptions& options = {});
  /// Waits for a repair in progress (a repair cannot be interrupted) but
  /// hands nothing more to the callback; a cloud still waiting is dropped.
  ~RepairStage();
  RepairStage(const RepairStage&) = delete;
  RepairStage& operator=(const RepairStage&) = delete;

  /// Puts a copy of `cloud` (and of `record`, what the camera saw of it:
  /// pointers to shared key frames) in the mailbox, replacing any cloud
  /// still waiting there. Never waits for a repair.
  void Submit(const ObjectCloud& cloud, const evidence::VisibilityRecord* record = nullptr);

  /// Waits until the mailbox is empty and the last cloud taken from it has
  /// been handed to the callback (end of session, tests). Not from the
  /// callback.
  void Drain();

  RepairStageStatus status() const;

 private:
  using Clock = std::chrono::steady_clock;
  void WorkerLoop();
  void RebaseLoop();
  // Worker, lock not held: the full repair of working_ (true if it threw:
  // working_ is left as it was); its verdict in *verdict.
  bool RepairInFull(std::string* verdict);
  // Worker, lock not held: an update of working_ into updated_ (then
  // swapped into working_), or working_ left as fused when there is no
  // base for it yet; a full repair in the background when one is due.
  enum class Update { kUpdated, kNoBase, kFailed };
  Update UpdateFromBase(std::string* verdict);

  const repair::RepairConfig config_;
  const RepairStageOptions options_;
  CloudCallback on_cloud_;

  mutable std::mutex mutex_;
  std::condition_variable wake_worker_;
  std::condition_variable idle_;
  ObjectCloud mailbox_;                        // the latest cloud, valid while has_mail_
  evidence::VisibilityRecord mailbox_record_;  // empty when none was given
  Clock::time_point mailbox_submitted_;
  bool has_mail_{false};
  struct Final {
    ObjectCloud cloud;
    evidence::VisibilityRecord record;
    Clock::time_point submitted;
  };
  std::deque<Final> finals_;  // once per grasp: allocation is fine here
  bool working_final_{false};
  ObjectCloud working_;  // the worker's; swapped with mailbox_, never copied
  evidence::VisibilityRecord working_record_;
  Clock::time_point working_submitted_;
  ObjectCloud updated_;  // the worker's update output, reused
  bool busy_{false};
  bool stop_{false};
  RepairStageStatus status_;
  SampleWindow update_ms_;  // guarded by mutex_
  SampleWindow full_ms_;

  // The base, shared by the worker (updates, a grasp's first cloud) and the
  // rebase thread (which swaps a new one in).
  std::mutex base_mutex_;
  repair::IncrementalRepair base_;
  // The rebase thread's job (guarded by mutex_): a fused cloud to repair
  // in full, and the base it builds.
  ObjectCloud rebase_job_;
  evidence::VisibilityRecord rebase_record_;
  bool has_rebase_job_{false};
  bool rebasing_{false};
  std::condition_variable wake_rebase_;

  std::thread worker_;  // last: start after everything above exists
  std::thread rebaser_;
};

}  // namespace graspfill::rt
