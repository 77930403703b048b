// SPDX-License-Identifier: BSD-3-Clause
// Counts the heap allocations made through operator new in a test binary,
// for the tests that check a hot path allocates nothing it could reuse.
// It replaces the global operator new and delete: include it in one test
// file of a binary only (each test binary here is one file).
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace graspfill::testing {
inline std::atomic<long> g_allocations{0};
// Allocations so far.
inline long Allocations() { return g_allocations.load(); }
}  // namespace graspfill::testing

// GCC cannot tell that these replace the global operators and warns that
// free() meets memory from "new".
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  ++graspfill::testing::g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
