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
// Threads: Submit and status() are safe from any thread and never wait for
// a repair (they take a short lock; Submit copies the cloud into a slot
// whose buffers are reused from cloud to cloud). The output callback runs
// on the stage's thread, once per repaired (or failed) cloud, in order.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "graspfill/repair/repairer.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt {

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
};

class RepairStage {
 public:
  using CloudCallback = std::function<void(const ObjectCloud&)>;

  /// Starts the thread. `config` is used as given (see
  /// GripperFrameRepairConfig for clouds in G). Throws
  /// std::invalid_argument on a bad config.
  RepairStage(const repair::RepairConfig& config, CloudCallback on_cloud);
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
  void WorkerLoop();

  const repair::RepairConfig config_;
  CloudCallback on_cloud_;

  mutable std::mutex mutex_;
  std::condition_variable wake_worker_;
  std::condition_variable idle_;
  ObjectCloud mailbox_;        // the latest cloud, valid while has_mail_
  evidence::VisibilityRecord mailbox_record_;  // empty when none was given
  bool has_mail_{false};
  struct Final {
    ObjectCloud cloud;
    evidence::VisibilityRecord record;
  };
  std::deque<Final> finals_;   // once per grasp: allocation is fine here
  bool working_final_{false};
  ObjectCloud working_;        // the worker's; swapped with mailbox_, never copied
  evidence::VisibilityRecord working_record_;
  bool busy_{false};
  bool stop_{false};
  RepairStageStatus status_;
  std::thread worker_;  // last: starts after everything above exists
};

}  // namespace graspfill::rt
