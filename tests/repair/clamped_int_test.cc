// SPDX-License-Identifier: BSD-3-Clause
// The repair's float-to-int conversions of extent-sized quantities
// (src/repair/clamped_int.hpp): values in range exactly as a cast, values
// beyond it (2.4e35 slabs, found by fuzz_repair), infinities and NaN the
// nearer bound, never undefined behaviour.
#include "clamped_int.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace graspfill::repair {
namespace {

constexpr int kMax = std::numeric_limits<int>::max();
constexpr int kMin = std::numeric_limits<int>::min();

TEST(ClampedInt, InRangeAsACastOutOfRangeTheNearerBound) {
  EXPECT_EQ(FloorToInt(2.7, 0, 10), 2);
  EXPECT_EQ(FloorToInt(-2.2, -5, 10), -3);
  EXPECT_EQ(CeilToInt(2.2, 0, 10), 3);
  EXPECT_EQ(RoundToInt(2.5, 0, 10), 3);
  EXPECT_EQ(RoundToInt(-2.5, -10, 10), -3);  // half away from zero, as std::lround
  EXPECT_EQ(FloorToInt(10.0, 0, 10), 10);    // the bounds themselves
  EXPECT_EQ(FloorToInt(0.0, 0, 10), 0);
  // The claw-hole fill's outline slabs of the fuzz input: 2.4e35.
  EXPECT_EQ(FloorToInt(2.38554e35, 0, 19999), 19999);
  EXPECT_EQ(FloorToInt(-2.38554e35, -1, 100), -1);
  EXPECT_EQ(FloorToInt(3e9, kMin, kMax), kMax);
  EXPECT_EQ(FloorToInt(-3e9, kMin, kMax), kMin);
  EXPECT_EQ(FloorToInt(static_cast<double>(kMax), kMin, kMax), kMax);
  EXPECT_EQ(CeilToInt(std::numeric_limits<double>::infinity(), 1, kMax), kMax);
  EXPECT_EQ(CeilToInt(-std::numeric_limits<double>::infinity(), 1, kMax), 1);
  EXPECT_EQ(FloorToInt(std::numeric_limits<double>::quiet_NaN(), -1, 5), -1);
}

}  // namespace
}  // namespace graspfill::repair
