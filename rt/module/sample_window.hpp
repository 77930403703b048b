// SPDX-License-Identifier: BSD-3-Clause
// The last N samples of a measurement (latencies, repair times) and their
// percentiles: a fixed ring, so a long session keeps a recent, bounded
// window and adding a sample never allocates.
//
// NOT thread safe: its owner guards it.
#pragma once

#include <cstddef>
#include <vector>

namespace graspfill::rt {

struct Percentiles {
  double p50{0.0}, p95{0.0}, p99{0.0}, max{0.0};
  size_t count{0};  ///< samples in the window
};

class SampleWindow {
 public:
  explicit SampleWindow(size_t capacity = 4096);
  void Add(double value);
  /// Nearest-rank percentiles of the window (all 0 when empty). Allocates
  /// nothing after the first call.
  Percentiles Summary() const;
  size_t count() const { return count_; }
  void Clear() { head_ = count_ = 0; }

 private:
  std::vector<double> ring_;
  size_t head_{0}, count_{0};
  mutable std::vector<double> scratch_;
};

}  // namespace graspfill::rt
