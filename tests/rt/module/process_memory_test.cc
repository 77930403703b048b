// SPDX-License-Identifier: BSD-3-Clause
// The heap reserve: what it touches stays mapped, and a thread's later
// allocations of TSDF-block size take those pages instead of faulting in
// new ones. Its own program: the settings are process-wide (and not run
// under the sanitizers, which bring their own allocator).
#include "module/process_memory.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <thread>
#include <vector>

namespace graspfill::rt {
namespace {

TEST(ProcessMemory, AReserveStaysMappedAndAThreadsBlocksReuseIt) {
  const double before_mb = ResidentMemoryMb();
  ASSERT_GT(before_mb, 0.0);
  ASSERT_TRUE(ReserveHeap(96));
  const double reserved_mb = ResidentMemoryMb();
  EXPECT_GE(reserved_mb - before_mb, 90.0) << "the reserve was handed back to the system";

  // 64 MB of 160 KB blocks (an Open3D TSDF block of 16^3 voxels is ~160 KB:
  // over glibc's default mmap threshold, each would be mapped anew), from a
  // thread other than the one that reserved (it would get an arena of its own).
  std::thread worker([] {
    std::vector<char*> blocks;
    for (int n = 0; n < 400; ++n) {
      auto* block = static_cast<char*>(std::malloc(160 << 10));
      ASSERT_NE(block, nullptr);
      for (size_t at = 0; at < (160u << 10); at += 4096) block[at] = 1;
      blocks.push_back(block);
    }
    for (char* block : blocks) std::free(block);
  });
  worker.join();
  EXPECT_LT(ResidentMemoryMb() - reserved_mb, 16.0) << "the blocks faulted in pages of their own";
}

}  // namespace
}  // namespace graspfill::rt
