#include "module/repair_stage.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <utility>

#include "module/cloud_repair.hpp"

namespace graspfill::rt {

RepairStage::RepairStage(const repair::RepairConfig& config, CloudCallback on_cloud)
    : config_(config), on_cloud_(std::move(on_cloud)) {
  config_.Validate();  // a bad config fails here, not once per cloud
  worker_ = std::thread(&RepairStage::WorkerLoop, this);
}

RepairStage::~RepairStage() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_worker_.notify_all();
  idle_.notify_all();
  worker_.join();
}

void RepairStage::Submit(const ObjectCloud& cloud, const evidence::VisibilityRecord* record) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++status_.submitted;
    if (cloud.is_final) {
      if (has_mail_ && mailbox_.grasp_id == cloud.grasp_id) {
        has_mail_ = false;  // older than the final of its grasp
        ++status_.superseded;
      }
      finals_.push_back(Final{cloud, record ? *record : evidence::VisibilityRecord()});
      ++status_.finals_pending;
      wake_worker_.notify_one();
      return;
    }
    if (has_mail_) ++status_.superseded;
    // Copy-assignment keeps the slot's buffers when they are big enough,
    // and they are after the first few clouds (they cycle with working_).
    mailbox_ = cloud;
    mailbox_record_ = record ? *record : evidence::VisibilityRecord();
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
  return status_;
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
      finals_.pop_front();
    } else {
      std::swap(working_, mailbox_);  // moves buffers, no copy
      std::swap(working_record_, mailbox_record_);
      has_mail_ = false;
    }
    busy_ = true;  // in the same critical section: Drain never sees a gap
    lock.unlock();

    const size_t points_in = working_.size();
    std::string verdict;
    bool failed = false;
    const auto start = std::chrono::steady_clock::now();
    try {
      verdict = RepairObjectCloud(config_, &working_,
                                  working_record_.empty() ? nullptr : &working_record_)
                    .StatusText();
    } catch (const std::exception& e) {
      failed = true;
      verdict = std::string("failed: ") + e.what();
    } catch (...) {
      failed = true;
      verdict = "failed: unknown exception";
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (failed) {
      // RepairObjectCloud leaves the cloud as it was: the fused cloud still
      // beats no cloud for the planner.
      std::fprintf(stderr, "graspfill repair stage: cloud seq %lld (%zu points) %s; "
                   "publishing it unrepaired\n",
                   static_cast<long long>(working_.seq), points_in, verdict.c_str());
    }

    lock.lock();
    if (failed) ++status_.failed;
    else ++status_.repaired;
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
        std::fprintf(stderr, "graspfill repair stage: output callback threw: %s\n", e.what());
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

}  // namespace graspfill::rt
