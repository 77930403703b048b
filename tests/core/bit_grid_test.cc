// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/bit_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace graspfill {
namespace {

const Eigen::AlignedBox3f kBox(Eigen::Vector3f(-0.1f, -0.1f, 0.0f), Eigen::Vector3f(0.1f, 0.1f, 0.2f));

TEST(BitGrid, SetCellsAreFoundAndOthersNot) {
  BitGrid grid;
  grid.Reset(kBox, 0.01f);
  const Eigen::Vector3f p(0.013f, -0.047f, 0.101f);
  EXPECT_FALSE(grid.Test(p));
  grid.Set(p);
  EXPECT_TRUE(grid.Test(p));
  EXPECT_TRUE(grid.Test(Eigen::Vector3f(0.019f, -0.041f, 0.109f)));   // same cell
  EXPECT_FALSE(grid.Test(Eigen::Vector3f(0.021f, -0.047f, 0.101f)));  // the next
}

TEST(BitGrid, DilationSetsTheNeighboursOnly) {
  BitGrid grid;
  grid.Reset(kBox, 0.01f);
  const Eigen::Vector3f p(0.005f, 0.005f, 0.105f);
  grid.Set(p, /*dilate=*/true);
  int set = 0;
  for (int dz = -2; dz <= 2; ++dz) {
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const bool near = std::abs(dx) <= 1 && std::abs(dy) <= 1 && std::abs(dz) <= 1;
        const bool is_set = grid.Test(p + 0.01f * Eigen::Vector3f(dx, dy, dz));
        EXPECT_EQ(is_set, near) << dx << " " << dy << " " << dz;
        set += is_set;
      }
    }
  }
  EXPECT_EQ(set, 27);
}

TEST(BitGrid, OutsideAndNonFiniteAreNeitherSetNorFound) {
  BitGrid grid;
  grid.Reset(kBox, 0.01f);
  const Eigen::Vector3f corner = kBox.min();
  grid.Set(corner - Eigen::Vector3f::Constant(0.001f), true);  // outside: ignored, not dilated in
  EXPECT_FALSE(grid.Test(corner));
  const Eigen::Vector3f nan(std::nanf(""), 0.0f, 0.1f);
  grid.Set(nan);
  EXPECT_FALSE(grid.Test(nan));
  EXPECT_FALSE(grid.Test(Eigen::Vector3f(5.0f, 0.0f, 0.1f)));
}

TEST(BitGrid, ResetClearsAndBadBoxesThrow) {
  BitGrid grid;
  grid.Reset(kBox, 0.01f);
  grid.Set(Eigen::Vector3f(0, 0, 0.1f));
  grid.Reset(kBox, 0.01f);
  EXPECT_FALSE(grid.Test(Eigen::Vector3f(0, 0, 0.1f)));
  EXPECT_THROW(grid.Reset(kBox, 0.0f), std::invalid_argument);
  EXPECT_THROW(grid.Reset(Eigen::AlignedBox3f(), 0.01f), std::invalid_argument);
  EXPECT_THROW(
      grid.Reset(Eigen::AlignedBox3f(Eigen::Vector3f::Zero(), Eigen::Vector3f::Constant(1e30f)), 1e-3f),
      std::invalid_argument);
}

}  // namespace
}  // namespace graspfill
