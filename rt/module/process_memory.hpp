// SPDX-License-Identifier: BSD-3-Clause
// The process's memory: its resident size (status, benchmarks) and a heap
// made ready for the real-time loop.
#pragma once

#include <cstddef>

namespace graspfill::rt {

/// Resident set size of this process [MB] (Linux: /proc/self/statm);
/// 0 when it cannot be read.
double ResidentMemoryMb();

/// Readies glibc's heap so that allocations on the frame path find pages
/// already mapped: one arena for every thread, no chunk mmap'd on its own,
/// nothing handed back to the system, and `reserve_mb` touched now and
/// freed into that arena. Why: a page the process touches first costs a
/// fault (5-10 us in a VM), and the first grasp faults in ~140 MB of new
/// TSDF blocks, claw tables and key frames, so its first frame took ~190
/// ms instead of ~20 (the bundled recording). Process-wide and for good:
/// the process keeps its high-water mark. Returns false (and changes what
/// it could) when the allocator refuses a setting.
bool ReserveHeap(size_t reserve_mb);

}  // namespace graspfill::rt
