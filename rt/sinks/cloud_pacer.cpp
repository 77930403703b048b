// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/cloud_pacer.hpp"

#include <chrono>
#include <exception>
#include <stdexcept>
#include <utility>

namespace graspfill::rt {

CloudPacer::CloudPacer(const CloudPacing& pacing, Send send) : pacing_(pacing), send_(std::move(send)) {
  if (pacing.slice_bytes == 0 || !(pacing.gap_ms >= 0.0) || pacing.copies < 1) {
    throw std::invalid_argument("CloudPacing: slice_bytes must be > 0, gap_ms >= 0 and copies >= 1");
  }
  thread_ = std::thread(&CloudPacer::Loop, this);
}

CloudPacer::~CloudPacer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void CloudPacer::Submit(const std::string& channel, std::vector<uint8_t> encoded_cloud) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queued_.size() >= kMaxQueued) {
      queued_.pop_front();
      ++dropped_;
    }
    queued_.push_back(Queued{channel, std::move(encoded_cloud)});
  }
  changed_.notify_all();
}

bool CloudPacer::Flush(int timeout_ms) {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                           [this] { return queued_.empty() && !sending_; });
}

int64_t CloudPacer::send_failures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return send_failures_;
}

int64_t CloudPacer::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

void CloudPacer::Loop() {
  const auto gap = std::chrono::duration<double, std::milli>(pacing_.gap_ms);
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || !queued_.empty(); });
    if (queued_.empty()) return;  // stopping, and all went out
    Queued next = std::move(queued_.front());
    queued_.pop_front();
    sending_ = true;
    lock.unlock();
    int64_t failures = 0;
    try {
      const std::vector<std::vector<uint8_t>> slices = io::EncodeCloudChunks(next.cloud, pacing_.slice_bytes);
      for (int copy = 0; copy < pacing_.copies; ++copy) {
        for (const std::vector<uint8_t>& slice : slices) {
          if (!send_(next.channel, slice)) ++failures;
          std::this_thread::sleep_for(gap);
        }
      }
    } catch (const std::exception&) {
      ++failures;  // not a cloud (the caller's bug) or out of memory: this one is not sent
    }
    lock.lock();
    send_failures_ += failures;
    sending_ = false;
    changed_.notify_all();
  }
}

}  // namespace graspfill::rt
