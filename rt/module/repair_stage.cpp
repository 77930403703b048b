// SPDX-License-Identifier: BSD-3-Clause
#include "module/repair_stage.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <utility>

#include "module/cloud_repair.hpp"
#include "module/error_text.hpp"

namespace graspfill::rt {

namespace {

// Full repairs in the background must never slow fusion down.
constexpr int kRebaseNice = 10;

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The repair's verdict, or the reason it threw (the cloud is then as it was).
template <typename RepairFn>
bool RunGuarded(RepairFn&& repair, std::string* verdict) {
  try {
    *verdict = repair();
    return false;
  } catch (const std::exception& e) {
    *verdict = "failed: " + ErrorText(e);
  } catch (...) {
    *verdict = "failed: unknown exception";
  }
  return true;
}

}  // namespace

RepairStage::RepairStage(const repair::RepairConfig& config, CloudCallback on_cloud,
                         const RepairStageOptions& options)
    : config_(config),
      options_(options),
      on_cloud_(std::move(on_cloud)),
      base_(options.incremental_config) {  // validates it
  config_.Validate();                      // a bad config fails here, not once per cloud
  worker_ = std::thread(&RepairStage::WorkerLoop, this);
  if (options_.incremental) rebaser_ = std::thread(&RepairStage::RebaseLoop, this);
}

RepairStage::~RepairStage() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_worker_.notify_all();
  wake_rebase_.notify_all();
  idle_.notify_all();
  worker_.join();
  if (rebaser_.joinable()) rebaser_.join();
}

void RepairStage::Submit(const ObjectCloud& cloud, const evidence::VisibilityRecord* record) {
  const Clock::time_point now = Clock::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++status_.submitted;
    if (cloud.is_final) {
      if (has_mail_ && mailbox_.grasp_id == cloud.grasp_id) {
        has_mail_ = false;  // older than the final of its grasp
        ++status_.superseded;
      }
      finals_.push_back(Final{cloud, record ? *record : evidence::VisibilityRecord(), now});
      ++status_.finals_pending;
      wake_worker_.notify_one();
      return;
    }
    if (has_mail_) ++status_.superseded;
    // Copy-assignment keeps the slot's buffers when they are big enough,
    // and they are after the first few clouds (they cycle with working_).
    mailbox_ = cloud;
    mailbox_record_ = record ? *record : evidence::VisibilityRecord();
    mailbox_submitted_ = now;
    has_mail_ = true;
  }
  wake_worker_.notify_one();
}

void RepairStage::Drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [&] { return stop_ || (!has_mail_ && finals_.empty() && !busy_); });
}

RepairStageStatus RepairStage::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  RepairStageStatus status = status_;
  status.update_ms = update_ms_.Summary();
  status.full_ms = full_ms_.Summary();
  return status;
}

bool RepairStage::RepairInFull(std::string* verdict) {
  const evidence::VisibilityRecord* record = working_record_.empty() ? nullptr : &working_record_;
  const Clock::time_point start = Clock::now();
  const bool failed =
      RunGuarded([&] { return RepairObjectCloud(config_, &working_, record).StatusText(); }, verdict);
  const double ms = MsSince(start);
  if (!failed && options_.incremental) {
    // The first cloud of a grasp, or a final: the base for what follows.
    std::lock_guard<std::mutex> base_lock(base_mutex_);
    try {
      base_.Rebase(working_, record);
    } catch (const std::exception& e) {
      base_.Reset();  // full repairs until a cloud fits the change grid
      std::fprintf(stderr, "graspfill repair stage: no incremental base: %s\n", ErrorText(e).c_str());
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  full_ms_.Add(ms);
  return failed;
}

RepairStage::Update RepairStage::UpdateFromBase(std::string* verdict) {
  const evidence::VisibilityRecord* record = working_record_.empty() ? nullptr : &working_record_;
  const Clock::time_point start = Clock::now();
  repair::UpdateReport report;
  try {
    std::lock_guard<std::mutex> base_lock(base_mutex_);
    report = base_.Update(working_, record, &updated_);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill repair stage: update failed (%s); repairing in full\n",
                 ErrorText(e).c_str());
    return Update::kFailed;
  }
  const bool no_base =
      report.rebase == repair::RebaseReason::kNoBase || report.rebase == repair::RebaseReason::kOtherGrasp;
  const double ms = MsSince(start);
  std::lock_guard<std::mutex> lock(mutex_);
  if (report.full_due() && !has_rebase_job_ && !rebasing_) {
    // The fused cloud goes to the rebase thread; the update's output (the
    // fused cloud itself when there is no base) is what the planner gets now.
    rebase_job_ = working_;  // copy-assignment reuses the job's buffers
    rebase_record_ = working_record_;
    has_rebase_job_ = true;
    status_.last_rebase_reason = repair::RebaseReasonName(report.rebase);
    wake_rebase_.notify_one();
  }
  if (no_base) {
    *verdict = "not repaired yet: the grasp's first full repair is running";
    return Update::kNoBase;  // working_ goes out as fused
  }
  updated_.timings.push_back({"repair_update", ms});
  update_ms_.Add(ms);
  *verdict = "updated";
  std::swap(working_, updated_);
  return Update::kUpdated;
}

void RepairStage::WorkerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_worker_.wait(lock, [&] { return stop_ || has_mail_ || !finals_.empty(); });
    if (stop_) return;
    working_final_ = !finals_.empty();
    if (working_final_) {
      std::swap(working_, finals_.front().cloud);
      std::swap(working_record_, finals_.front().record);
      working_submitted_ = finals_.front().submitted;
      finals_.pop_front();
    } else {
      std::swap(working_, mailbox_);  // moves buffers, no copy
      std::swap(working_record_, mailbox_record_);
      working_submitted_ = mailbox_submitted_;
      has_mail_ = false;
    }
    busy_ = true;  // in the same critical section: Drain never sees a gap
    lock.unlock();

    const double wait_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - working_submitted_).count();
    const Clock::time_point start = Clock::now();
    const size_t points_in = working_.size();
    const Clock::time_point arrival = working_.newest_frame_arrival;  // not the repair's to keep
    std::string verdict;
    bool failed = false;
    const Update update =
        options_.incremental && !working_final_ ? UpdateFromBase(&verdict) : Update::kFailed;
    const bool updated = update == Update::kUpdated;
    const bool unrepaired = update == Update::kNoBase;
    if (!updated && !unrepaired) failed = RepairInFull(&verdict);
    const double ms = MsSince(start);
    if (failed) {
      // RepairObjectCloud leaves the cloud as it was: the fused cloud still
      // beats no cloud for the planner.
      std::fprintf(stderr,
                   "graspfill repair stage: cloud seq %lld (%zu points) %s; "
                   "publishing it unrepaired\n",
                   static_cast<long long>(working_.seq), points_in, verdict.c_str());
    }
    working_.newest_frame_arrival = arrival;
    working_.timings.push_back({"latency_repair_wait", wait_ms});
    working_.timings.push_back({"latency_repair", ms});
    if (arrival != Clock::time_point{}) {
      working_.timings.push_back({"latency_frame_to_repaired", MsSince(arrival)});
    }

    lock.lock();
    if (failed)
      ++status_.failed;
    else if (unrepaired)
      ++status_.unrepaired;
    else
      ++status_.repaired;
    if (updated)
      ++status_.updates;
    else if (!failed && !unrepaired)
      ++status_.full_published;
    status_.last_repair_ms = ms;
    status_.last_points_in = points_in;
    status_.last_points_out = working_.size();
    status_.last_status = std::move(verdict);
    const bool hand_on = !stop_ && on_cloud_;  // nothing after the destructor began
    lock.unlock();

    bool published = false;
    if (hand_on) {
      // An exception escaping this thread would end the process.
      try {
        on_cloud_(working_);
        published = true;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "graspfill repair stage: output callback threw: %s\n", ErrorText(e).c_str());
      } catch (...) {
        std::fprintf(stderr, "graspfill repair stage: output callback threw\n");
      }
    }

    lock.lock();
    if (published) ++status_.published;
    if (working_final_) --status_.finals_pending;
    busy_ = false;
    idle_.notify_all();
  }
}

void RepairStage::RebaseLoop() {
  // Linux: a thread's nice value is its own (setpriority on its tid).
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kRebaseNice);
  ObjectCloud cloud;
  evidence::VisibilityRecord record;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_rebase_.wait(lock, [&] { return stop_ || has_rebase_job_; });
    if (stop_) return;
    std::swap(cloud, rebase_job_);
    std::swap(record, rebase_record_);
    has_rebase_job_ = false;
    rebasing_ = true;
    lock.unlock();

    const Clock::time_point start = Clock::now();
    std::string verdict;
    const bool failed = RunGuarded(
        [&] { return RepairObjectCloud(config_, &cloud, record.empty() ? nullptr : &record).StatusText(); },
        &verdict);
    const double ms = MsSince(start);
    bool rebased = false;
    if (!failed) {
      // Built apart, swapped in: updates wait only for the swap.
      repair::IncrementalRepair fresh(options_.incremental_config);
      try {
        fresh.Rebase(cloud, record.empty() ? nullptr : &record);
        std::lock_guard<std::mutex> base_lock(base_mutex_);
        std::swap(base_, fresh);
        rebased = true;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "graspfill repair stage: no incremental base: %s\n", ErrorText(e).c_str());
      }
    } else {
      std::fprintf(stderr, "graspfill repair stage: background repair of cloud seq %lld %s\n",
                   static_cast<long long>(cloud.seq), verdict.c_str());
    }

    lock.lock();
    full_ms_.Add(ms);
    if (rebased) ++status_.rebases;
    rebasing_ = false;
  }
}

}  // namespace graspfill::rt
