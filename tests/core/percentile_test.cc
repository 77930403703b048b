// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/percentile.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace graspfill {
namespace {

TEST(PercentileTest, InterpolatesLinearlyBetweenOrderStatistics) {
  EXPECT_DOUBLE_EQ(Percentile({4.0, 1.0, 3.0, 2.0}, 50.0), 2.5);
  EXPECT_DOUBLE_EQ(Percentile({4.0, 1.0, 3.0, 2.0}, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile({4.0, 1.0, 3.0, 2.0}, 100.0), 4.0);
  // Rank 0.9 * 4 = 3.6 of {0, 10, 20, 30, 40}: 30 + 0.6 * 10.
  EXPECT_DOUBLE_EQ(Percentile({40.0, 0.0, 30.0, 10.0, 20.0}, 90.0), 36.0);
  EXPECT_DOUBLE_EQ(Percentile({7.0}, 95.0), 7.0);
}

TEST(PercentileTest, RejectsNoValuesAndOutOfRangeQ) {
  EXPECT_THROW(Percentile({}, 50.0), std::invalid_argument);
  EXPECT_THROW(Percentile({1.0}, 101.0), std::invalid_argument);
  EXPECT_THROW(Percentile({1.0}, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill
