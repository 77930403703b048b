// SPDX-License-Identifier: BSD-3-Clause
#include "module/process_memory.hpp"

#include <malloc.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace graspfill::rt {

double ResidentMemoryMb() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return 0.0;
  unsigned long long size_pages = 0, resident_pages = 0;
  const int read = std::fscanf(f, "%llu %llu", &size_pages, &resident_pages);
  std::fclose(f);
  if (read != 2) return 0.0;
  const long page = sysconf(_SC_PAGESIZE);
  return static_cast<double>(resident_pages) * static_cast<double>(page > 0 ? page : 4096) /
         (1024.0 * 1024.0);
}

bool ReserveHeap(size_t reserve_mb) {
  // Threads would otherwise get arenas of their own, which the reserve
  // below does not reach.
  bool ok = mallopt(M_ARENA_MAX, 1) == 1;
  ok = mallopt(M_MMAP_MAX, 0) == 1 && ok;         // big chunks from the arena too
  ok = mallopt(M_TRIM_THRESHOLD, -1) == 1 && ok;  // freed pages stay mapped
  if (reserve_mb == 0) return ok;
  const size_t bytes = reserve_mb << 20;
  auto* block = static_cast<volatile char*>(std::malloc(bytes));
  if (block == nullptr) return false;
  const long page = sysconf(_SC_PAGESIZE);
  for (size_t at = 0; at < bytes; at += static_cast<size_t>(page > 0 ? page : 4096)) block[at] = 0;
  std::free(const_cast<char*>(block));
  return ok;
}

}  // namespace graspfill::rt
