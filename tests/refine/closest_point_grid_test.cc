// SPDX-License-Identifier: BSD-3-Clause
// The closest-point table answers, for every cell, exactly what a scan of
// all the points would: the first of the nearest to the cell's centre
// within the band, or none.
#include "graspfill/refine/closest_point_grid.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace graspfill::refine {
namespace {

// The scan the table stands for, in the same float arithmetic.
int ScanNearest(const std::vector<Eigen::Vector3f>& points, int stride, const Eigen::Vector3f& centre,
                float band) {
  int best = -1;
  float best_d2 = band * band;
  for (size_t k = 0; k < points.size(); k += static_cast<size_t>(stride)) {
    const float d2 = (centre - points[k]).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = static_cast<int>(k);
    }
  }
  return best;
}

// Points on two crossing sheets (a claw's faces) plus scattered ones.
std::vector<Eigen::Vector3f> SheetPoints(std::mt19937* rng) {
  std::uniform_real_distribution<float> u(0.0f, 0.04f);
  std::vector<Eigen::Vector3f> points;
  for (int n = 0; n < 400; ++n) points.emplace_back(u(*rng), u(*rng), 0.02f);
  for (int n = 0; n < 400; ++n) points.emplace_back(0.015f, u(*rng), u(*rng));
  for (int n = 0; n < 100; ++n) points.emplace_back(u(*rng), u(*rng), u(*rng));
  return points;
}

TEST(ClosestPointGrid, EveryCellAnswersAsAScanOfAllPoints) {
  std::mt19937 rng(7);
  const std::vector<Eigen::Vector3f> points = SheetPoints(&rng);
  for (const auto& [stride, cell_m, band_m] :
       {std::tuple{1, 0.0015, 0.006}, std::tuple{2, 0.004, 0.026}, std::tuple{3, 0.002, 0.0031}}) {
    ClosestPointGrid grid;
    grid.Build(points, stride, cell_m, band_m);
    std::uniform_real_distribution<float> q(-0.035f, 0.075f);  // past the band on every side
    int found = 0, none = 0;
    for (int n = 0; n < 20000; ++n) {
      const Eigen::Vector3f p(q(rng), q(rng), q(rng));
      const int expected = ScanNearest(points, stride, grid.CellCentre(p), static_cast<float>(band_m));
      const int got = grid.Nearest(p);
      // Off the table the answer is none, and so must the scan's be.
      ASSERT_EQ(got, expected) << "stride " << stride << " cell " << cell_m << " at " << p.transpose();
      (got >= 0 ? found : none) += 1;
    }
    // Both answers occur, so the comparison covers both.
    EXPECT_GT(found, 200);
    EXPECT_GT(none, 200);
  }
}

TEST(ClosestPointGrid, NoPointsGiveAnEmptyTable) {
  ClosestPointGrid grid;
  grid.Build({}, 1, 0.002, 0.006);
  EXPECT_EQ(grid.Nearest(Eigen::Vector3f::Zero()), -1);
}

}  // namespace
}  // namespace graspfill::refine
