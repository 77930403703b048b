// SPDX-License-Identifier: BSD-3-Clause
// Wall-clock timing of pipeline stages and repair steps (steady clock): a
// scope's time, accumulated per stage or appended as a named timing.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill {

/// Accumulated time of one stage [ms] and how often it ran.
struct StageTotal {
  double total_ms{0.0};
  double last_ms{0.0};
  int64_t count{0};
  double mean_ms() const { return count ? total_ms / count : 0.0; }
};

/// Times its scope: adds the time between construction and destruction to
/// a StageTotal, or appends it to a list of timings under a stage's name.
class ScopedStageTimer {
 public:
  explicit ScopedStageTimer(StageTotal* total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  /// `stage` must outlive the timer (a string literal).
  ScopedStageTimer(std::vector<StageTiming>* timings, const char* stage)
      : timings_(timings), stage_(stage), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStageTimer() {
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    if (total_ != nullptr) {
      total_->last_ms = ms;
      total_->total_ms += ms;
      ++total_->count;
    } else {
      timings_->push_back({stage_, ms});
    }
  }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  StageTotal* total_{nullptr};
  std::vector<StageTiming>* timings_{nullptr};
  const char* stage_{nullptr};
  std::chrono::steady_clock::time_point start_;
};

}  // namespace graspfill
