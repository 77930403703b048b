// SPDX-License-Identifier: BSD-3-Clause
// Wall-clock timing of pipeline stages (steady clock), accumulated per stage.
#pragma once

#include <chrono>

namespace graspfill {

/// Accumulated time of one stage [ms] and how often it ran.
struct StageTotal {
  double total_ms{0.0};
  double last_ms{0.0};
  int64_t count{0};
  double mean_ms() const { return count ? total_ms / count : 0.0; }
};

/// Adds the time between construction and destruction to a StageTotal.
class ScopedStageTimer {
 public:
  explicit ScopedStageTimer(StageTotal* total)
      : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStageTimer() {
    const double ms = std::chrono::duration<double, std::milli>(
                          std::chrono::steady_clock::now() - start_).count();
    total_->last_ms = ms;
    total_->total_ms += ms;
    ++total_->count;
  }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  StageTotal* total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace graspfill
