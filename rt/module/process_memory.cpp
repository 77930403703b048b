#include "module/process_memory.hpp"

#include <unistd.h>

#include <cstdio>

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

}  // namespace graspfill::rt
