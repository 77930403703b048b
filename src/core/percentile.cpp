// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/percentile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace graspfill {

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) {
    throw std::invalid_argument("graspfill: percentile of no values");
  }
  if (!(q >= 0.0 && q <= 100.0)) {
    throw std::invalid_argument("graspfill: percentile must be in [0, 100], got " + std::to_string(q));
  }
  std::sort(values.begin(), values.end());
  const double rank = q / 100.0 * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(rank));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  const double frac = rank - static_cast<double>(lo);
  return values[lo] + frac * (values[hi] - values[lo]);
}

}  // namespace graspfill
