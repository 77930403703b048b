// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/openmp_threads.hpp"

#include <omp.h>

#include <stdexcept>
#include <string>

namespace graspfill {

namespace {

// OpenMP's settings as the process started (OMP_NUM_THREADS,
// OMP_MAX_ACTIVE_LEVELS, else libgomp's own: a thread per logical core),
// read once: kAtStart reads them during static initialization, before
// main (or an embedder) changes the main thread's.
struct OpenMpDefaults {
  int max_threads;
  int max_active_levels;
};
const OpenMpDefaults& ProcessDefaults() {
  static const OpenMpDefaults defaults{omp_get_max_threads(), omp_get_max_active_levels()};
  return defaults;
}
[[maybe_unused]] const OpenMpDefaults& kAtStart = ProcessDefaults();

}  // namespace

void CheckOpenMpThreads(const char* field, int num_threads) {
  if (num_threads < 0 || num_threads > kMaxOpenMpThreads) {
    throw std::invalid_argument(std::string(field) + " " + std::to_string(num_threads) + ": expected 0..." +
                                std::to_string(kMaxOpenMpThreads) + " (0: OpenMP's own count)");
  }
}

void SetOpenMpThreads(int num_threads) {
  CheckOpenMpThreads("num_threads", num_threads);
  if (num_threads == 0) {
    omp_set_num_threads(ProcessDefaults().max_threads);
    omp_set_max_active_levels(ProcessDefaults().max_active_levels);
    return;
  }
  if (num_threads == 1) {
    // No region can be active: every one, whatever team it names, runs on
    // the calling thread.
    omp_set_max_active_levels(0);
    return;
  }
  omp_set_num_threads(num_threads);
  // One active level: the outer region gets up to N threads, nested ones one
  // (N x N threads otherwise).
  omp_set_max_active_levels(1);
}

ScopedOpenMpThreads::ScopedOpenMpThreads(int num_threads) {
  CheckOpenMpThreads("num_threads", num_threads);
  saved_max_threads_ = omp_get_max_threads();
  saved_max_active_levels_ = omp_get_max_active_levels();
  SetOpenMpThreads(num_threads);
}

ScopedOpenMpThreads::~ScopedOpenMpThreads() {
  omp_set_num_threads(saved_max_threads_);
  omp_set_max_active_levels(saved_max_active_levels_);
}

ScopedOpenMpFixedTeam::ScopedOpenMpFixedTeam(int requested) {
  if (omp_get_max_active_levels() == 0 || omp_get_max_threads() >= requested) return;
  saved_max_active_levels_ = omp_get_max_active_levels();
  changed_ = true;
  omp_set_max_active_levels(0);
}

ScopedOpenMpFixedTeam::~ScopedOpenMpFixedTeam() {
  if (changed_) omp_set_max_active_levels(saved_max_active_levels_);
}

}  // namespace graspfill
