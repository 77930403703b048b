// SPDX-License-Identifier: BSD-3-Clause
// The thread count set in code: team sizes of OpenMP regions inside and
// after the scopes, and on other threads. Runs without OMP_THREAD_LIMIT
// (tests/CMakeLists.txt, OPENMP_UNLIMITED), so a region gets the team it
// asks for unless these settings say otherwise.
#include "graspfill/core/openmp_threads.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <stdexcept>
#include <thread>

namespace graspfill {
namespace {

// The team a region started here gets: `asked` threads named by the
// region (as Open3D's do), or OpenMP's count when 0.
int TeamSize(int asked) {
  int size = 0;
  if (asked > 0) {
#pragma omp parallel num_threads(asked)
    {
#pragma omp single
      size = omp_get_num_threads();
    }
  } else {
#pragma omp parallel
    {
#pragma omp single
      size = omp_get_num_threads();
    }
  }
  return size;
}

TEST(ScopedOpenMpThreads, OneThreadHoldsEvenForRegionsThatNameTheirTeam) {
  ASSERT_EQ(TeamSize(4), 4) << "OMP_THREAD_LIMIT or OMP_DYNAMIC set: nothing to observe";
  {
    const ScopedOpenMpThreads one(1);
    EXPECT_EQ(TeamSize(4), 1);
    EXPECT_EQ(TeamSize(0), 1);
  }
  EXPECT_EQ(TeamSize(4), 4);  // restored
}

TEST(ScopedOpenMpThreads, AtMostNAndRestoredAfter) {
  const int max_threads = omp_get_max_threads();
  const int levels = omp_get_max_active_levels();
  {
    const ScopedOpenMpThreads three(3);
    EXPECT_EQ(omp_get_max_threads(), 3);
    EXPECT_EQ(TeamSize(0), 3);
    // A region naming a larger team is not capped by the count...
    EXPECT_EQ(TeamSize(8), 8);
    {
      // ...unless wrapped: one thread, the count being below its team.
      const ScopedOpenMpFixedTeam fixed(8);
      EXPECT_EQ(TeamSize(8), 1);
    }
    {
      const ScopedOpenMpFixedTeam fixed(2);  // within the count: as asked
      EXPECT_EQ(TeamSize(2), 2);
    }
    EXPECT_EQ(TeamSize(8), 8);
  }
  EXPECT_EQ(omp_get_max_threads(), max_threads);
  EXPECT_EQ(omp_get_max_active_levels(), levels);
}

// 0 is OpenMP's own count as the process started (no OMP_* variables here:
// a thread per logical core), whatever the thread set since.
TEST(ScopedOpenMpThreads, ZeroIsOpenMpsOwnCount) {
  int fresh_thread = 0;
  std::thread t([&] { fresh_thread = omp_get_max_threads(); });
  t.join();
  omp_set_num_threads(fresh_thread + 3);
  omp_set_max_active_levels(0);
  {
    const ScopedOpenMpThreads zero(0);
    EXPECT_EQ(omp_get_max_threads(), fresh_thread);
    EXPECT_EQ(TeamSize(0), fresh_thread);
  }
  EXPECT_EQ(omp_get_max_threads(), fresh_thread + 3);
  EXPECT_EQ(omp_get_max_active_levels(), 0);
}

TEST(ScopedOpenMpThreads, OtherThreadsKeepTheirSettings) {
  const ScopedOpenMpThreads one(1);
  int other = 0;
  std::thread t([&] { other = TeamSize(4); });
  t.join();
  EXPECT_EQ(other, 4);
  EXPECT_EQ(TeamSize(4), 1);
}

TEST(ScopedOpenMpThreads, ScopesNest) {
  const ScopedOpenMpThreads two(2);
  {
    const ScopedOpenMpThreads one(1);
    EXPECT_EQ(TeamSize(0), 1);
  }
  EXPECT_EQ(TeamSize(0), 2);
}

TEST(ScopedOpenMpThreads, OutOfRangeIsRefused) {
  EXPECT_THROW(ScopedOpenMpThreads(-1), std::invalid_argument);
  EXPECT_THROW(ScopedOpenMpThreads(kMaxOpenMpThreads + 1), std::invalid_argument);
  EXPECT_THROW(SetOpenMpThreads(-1), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill
