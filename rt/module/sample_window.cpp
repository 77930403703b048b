// SPDX-License-Identifier: BSD-3-Clause
#include "module/sample_window.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace graspfill::rt {

SampleWindow::SampleWindow(size_t capacity) {
  if (capacity == 0) throw std::invalid_argument("SampleWindow: capacity must be >= 1");
  ring_.resize(capacity);
  scratch_.reserve(capacity);
}

void SampleWindow::Add(double value) {
  ring_[(head_ + count_) % ring_.size()] = value;
  if (count_ < ring_.size())
    ++count_;
  else
    head_ = (head_ + 1) % ring_.size();
}

Percentiles SampleWindow::Summary() const {
  Percentiles out;
  out.count = count_;
  if (count_ == 0) return out;
  scratch_.clear();
  for (size_t i = 0; i < count_; ++i) scratch_.push_back(ring_[(head_ + i) % ring_.size()]);
  std::sort(scratch_.begin(), scratch_.end());
  // Nearest rank: the smallest sample with at least q of them at or below.
  const auto rank = [&](double q) {
    const size_t r = static_cast<size_t>(std::ceil(q * static_cast<double>(count_)));
    return scratch_[std::min(count_, std::max<size_t>(r, 1)) - 1];
  };
  out.p50 = rank(0.50);
  out.p95 = rank(0.95);
  out.p99 = rank(0.99);
  out.max = scratch_.back();
  return out;
}

}  // namespace graspfill::rt
