// SPDX-License-Identifier: BSD-3-Clause
#include "geometry/gap_grid.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "graspfill/core/random.hpp"

namespace graspfill::repair::geometry {
namespace {

bool BruteForceAnyWithin(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& q, double gap) {
  const float r2 = static_cast<float>(gap * gap);
  for (const Eigen::Vector3f& p : points) {
    if ((p - q).squaredNorm() <= r2) return true;
  }
  return false;
}

Eigen::Vector2d Xy(const Eigen::Vector3f& p) { return Eigen::Vector2d(p.x(), p.y()); }

// The grid's answer is the brute force's, queries anywhere on the grid,
// at the gap of the cells and with cells coarsened for a wide box.
TEST(GapGrid, AnswersAsBruteForce) {
  Rng rng(3);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 1500; ++i) {
    points.emplace_back(static_cast<float>(0.1 * rng.Uniform()), static_cast<float>(0.05 * rng.Uniform()),
                        static_cast<float>(0.02 * rng.Uniform()));
  }
  for (const double gap : {0.002, 0.004}) {
    // The grid's box: the points' (with the query margin); and one so wide
    // that its cells are coarsened (1 km: 1e11 cells of the gap).
    for (const double wide : {0.0, 1000.0}) {
      GapGrid grid(Eigen::Vector2d(-gap - wide, -gap), Eigen::Vector2d(0.1 + gap + wide, 0.05 + gap), gap);
      ASSERT_TRUE(grid.valid());
      EXPECT_EQ(grid.cell() > gap, wide > 0.0);
      for (const Eigen::Vector3f& p : points) grid.Add(Xy(p), p);
      grid.Build();
      int hits = 0, misses = 0;
      for (int t = 0; t < 2000; ++t) {
        const Eigen::Vector3f q(static_cast<float>(0.1 * rng.Uniform()),
                                static_cast<float>(0.05 * rng.Uniform()),
                                static_cast<float>(0.04 * rng.Uniform() - 0.01));
        const bool any = grid.AnyWithin(Xy(q), q);
        ASSERT_EQ(any, BruteForceAnyWithin(points, q, gap)) << q.transpose() << " gap " << gap;
        any ? ++hits : ++misses;
      }
      EXPECT_GT(hits, 100);
      EXPECT_GT(misses, 100);
    }
  }
}

TEST(GapGrid, PointsOffTheGridAndNoGapFindNothing) {
  GapGrid grid(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), 0.1);
  const Eigen::Vector3f outside(1.5f, 0.5f, 0.0f);
  grid.Add(Xy(outside), outside);  // left out: off the grid
  const Eigen::Vector3f inside(0.95f, 0.5f, 0.0f);
  grid.Add(Xy(inside), inside);
  grid.Build();
  EXPECT_TRUE(grid.AnyWithin(Xy(inside), inside));
  EXPECT_FALSE(grid.AnyWithin(Eigen::Vector2d(1.45, 0.5), Eigen::Vector3f(1.45f, 0.5f, 0.0f)));
  for (const double gap : {0.0, -1.0, std::nan("")}) {
    GapGrid none(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), gap);
    EXPECT_FALSE(none.valid());
    none.Add(Xy(inside), inside);
    none.Build();
    EXPECT_FALSE(none.AnyWithin(Xy(inside), inside));
  }
  GapGrid nan_box(Eigen::Vector2d(0, std::nan("")), Eigen::Vector2d(1, 1), 0.1);
  EXPECT_FALSE(nan_box.valid());
}

}  // namespace
}  // namespace graspfill::repair::geometry
