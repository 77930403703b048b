// SPDX-License-Identifier: BSD-3-Clause
// The OpenMP thread count of graspfill's calls, set in code rather than
// through OMP_NUM_THREADS / OMP_THREAD_LIMIT before the process starts.
//
// OpenMP keeps its settings per thread (libgomp: nthreads-var and
// max-active-levels-var are the calling thread's), so a setting made here
// touches neither the embedder's other threads nor, once the scope ends,
// its own OpenMP code on this thread. Open3D's TSDF integration asks for a
// team of its own size (one thread per physical core), which
// omp_set_num_threads does not cap; max-active-levels 0 does, for every
// region (a region started at max-active-levels 0 runs on the calling
// thread alone).
//
// Why one thread is graspfill's default: on 2 busy cores Open3D's team per
// voxel block made a frame's integration 15-30x slower than one thread
// (131-223 ms vs 6-9 ms, fusion/tsdf_fusion.hpp), and the results are the
// same bytes at any count (tests/core/openmp_threads_test.cc).
#pragma once

namespace graspfill {

/// Largest thread count a config accepts.
constexpr int kMaxOpenMpThreads = 1024;

/// What a `num_threads` field asks of the OpenMP regions started inside a
/// call (Open3D's and any other library's on the calling thread):
///  - 0: OpenMP's own settings, as the process started, whatever the
///    calling thread set since (OMP_NUM_THREADS, OMP_MAX_ACTIVE_LEVELS, or
///    with no OMP_* variables a thread per logical core; Open3D's TSDF
///    integration then takes a team per physical core);
///  - 1: every region runs on the calling thread alone;
///  - N > 1: at most N threads per region: omp_set_num_threads(N) for the
///    regions that take OpenMP's count, and one thread for the regions
///    that name a larger count of their own (see ScopedOpenMpFixedTeam).
/// Nested regions stay on one thread.
///
/// Sets the calling thread's OpenMP settings for the object's lifetime and
/// restores them when it ends (scopes nest). Not to be used inside an
/// OpenMP region. @throws std::invalid_argument outside 0..kMaxOpenMpThreads.
class ScopedOpenMpThreads {
 public:
  explicit ScopedOpenMpThreads(int num_threads);
  ~ScopedOpenMpThreads();
  ScopedOpenMpThreads(const ScopedOpenMpThreads&) = delete;
  ScopedOpenMpThreads& operator=(const ScopedOpenMpThreads&) = delete;

 private:
  int saved_max_threads_{0};
  int saved_max_active_levels_{0};
};

/// Around a library call whose OpenMP regions name their own team size
/// (`requested` threads, e.g. Open3D's utility::EstimateMaxThreads()):
/// when the calling thread's settings allow fewer threads than that
/// (omp_get_max_threads() < requested, as ScopedOpenMpThreads(N) leaves
/// them), its regions run on one thread for the object's lifetime, so that
/// the count set stays an upper bound; otherwise nothing changes.
class ScopedOpenMpFixedTeam {
 public:
  explicit ScopedOpenMpFixedTeam(int requested);
  ~ScopedOpenMpFixedTeam();
  ScopedOpenMpFixedTeam(const ScopedOpenMpFixedTeam&) = delete;
  ScopedOpenMpFixedTeam& operator=(const ScopedOpenMpFixedTeam&) = delete;

 private:
  bool changed_{false};
  int saved_max_active_levels_{0};
};

/// The calling thread's OpenMP settings as `num_threads` asks (see
/// ScopedOpenMpThreads), not restored: for a thread its caller owns (the
/// CLI's main thread). @throws std::invalid_argument as above.
void SetOpenMpThreads(int num_threads);

/// "<field> N: expected 0...1024 (0: OpenMP's own count)" when out of
/// range, else nothing.
/// @throws std::invalid_argument naming `field`.
void CheckOpenMpThreads(const char* field, int num_threads);

}  // namespace graspfill
