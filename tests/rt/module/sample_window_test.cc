// SPDX-License-Identifier: BSD-3-Clause
#include "module/sample_window.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace graspfill::rt {
namespace {

TEST(SampleWindow, NearestRankPercentiles) {
  SampleWindow w(1000);
  for (int i = 100; i >= 1; --i) w.Add(i);  // 1..100, in any order
  const Percentiles p = w.Summary();
  EXPECT_EQ(p.count, 100u);
  EXPECT_DOUBLE_EQ(p.p50, 50);
  EXPECT_DOUBLE_EQ(p.p95, 95);
  EXPECT_DOUBLE_EQ(p.p99, 99);
  EXPECT_DOUBLE_EQ(p.max, 100);
}

TEST(SampleWindow, KeepsTheLastSamplesOnly) {
  SampleWindow w(4);
  for (double v : {1000.0, 1.0, 2.0, 3.0, 4.0}) w.Add(v);
  const Percentiles p = w.Summary();
  EXPECT_EQ(p.count, 4u);
  EXPECT_DOUBLE_EQ(p.max, 4.0);  // the 1000 fell out
  EXPECT_DOUBLE_EQ(p.p50, 2.0);
}

TEST(SampleWindow, EmptyAndBadCapacity) {
  SampleWindow w(3);
  EXPECT_EQ(w.Summary().count, 0u);
  EXPECT_DOUBLE_EQ(w.Summary().max, 0.0);
  w.Add(7.0);
  w.Clear();
  EXPECT_EQ(w.Summary().count, 0u);
  EXPECT_THROW(SampleWindow(0), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::rt
