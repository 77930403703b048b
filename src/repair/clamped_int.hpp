// SPDX-License-Identifier: BSD-3-Clause
// Float-to-int conversions of quantities that grow with a cloud's extent
// (slab counts, slab and cell indices, samples along a span): a stray point
// 1e35 m away makes them exceed int, and converting such a double to int
// is undefined behaviour (found by fuzz_repair: 2.4e35 slabs in the
// claw-hole fill). Each call names the range its caller can use; a value
// outside it comes back as the nearer bound, so a caller's own range check
// (k < 0 || k >= count) still rejects it. Internal to src/repair.
#pragma once

#include <cmath>

namespace graspfill::repair {

/// `x` (already whole, or truncated toward zero) as an int in [lo, hi]:
/// the nearer bound where it lies outside, `lo` for NaN.
inline int ClampedInt(double x, int lo, int hi) {
  if (!(x >= lo)) return lo;  // NaN too
  if (x >= hi) return hi;
  return static_cast<int>(x);
}

/// floor(x), ceil(x), round(x) (half away from zero) as ClampedInt.
inline int FloorToInt(double x, int lo, int hi) { return ClampedInt(std::floor(x), lo, hi); }
inline int CeilToInt(double x, int lo, int hi) { return ClampedInt(std::ceil(x), lo, hi); }
inline int RoundToInt(double x, int lo, int hi) { return ClampedInt(std::round(x), lo, hi); }

}  // namespace graspfill::repair
