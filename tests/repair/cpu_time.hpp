// SPDX-License-Identifier: BSD-3-Clause
// CPU-time measurements for the repair tests' timings (printed, not
// asserted).
#pragma once

#include <algorithm>
#include <ctime>

namespace graspfill::repair::testing {

/// Process CPU time [ms]: steadier than wall time on a shared machine; with
/// OMP_THREAD_LIMIT=1 (as ctest runs the tests) it is one core's time.
inline double CpuMs() { return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

/// The least CPU time [ms] that fn() takes in three runs.
template <typename Fn>
double BestOf3CpuMs(const Fn& fn) {
  double best = 1e30;
  for (int r = 0; r < 3; ++r) {
    const double t0 = CpuMs();
    fn();
    best = std::min(best, CpuMs() - t0);
  }
  return best;
}

}  // namespace graspfill::repair::testing
