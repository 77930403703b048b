// The process's resident memory, for the status and the benchmarks.
#pragma once

namespace graspfill::rt {

/// Resident set size of this process [MB] (Linux: /proc/self/statm);
/// 0 when it cannot be read.
double ResidentMemoryMb();

}  // namespace graspfill::rt
