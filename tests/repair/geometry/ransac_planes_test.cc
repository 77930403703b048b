// SPDX-License-Identifier: BSD-3-Clause
#include "geometry/ransac_planes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "graspfill/core/random.hpp"

namespace graspfill::repair::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

// Samples of a box's outline edges (x in [0, 0.1], y in [0, 0.06], z in
// [0, 0.15]): its top rim (z = top) and the vertical edges, 1 mm noise.
std::vector<Vec3> BoxEdges(double top, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3> points;
  const auto noise = [&] { return 0.001 * (2.0 * rng.Uniform() - 1.0); };
  for (int i = 0; i < 400; ++i) {  // the rim: around the top rectangle
    const double t = rng.Uniform() * 0.32;
    Vec3 p = t < 0.1    ? Vec3(t, 0, top)
             : t < 0.16 ? Vec3(0.1, t - 0.1, top)
             : t < 0.26 ? Vec3(0.26 - t, 0.06, top)
                        : Vec3(0, 0.32 - t, top);
    points.push_back(p + Vec3(noise(), noise(), noise()));
  }
  for (int i = 0; i < 400; ++i) {  // the four vertical edges
    const double x = (i % 2) * 0.1, y = ((i / 2) % 2) * 0.06;
    points.push_back(Vec3(x, y, rng.Uniform() * top) + Vec3(noise(), noise(), noise()));
  }
  return points;
}

// The cloud: the box's faces below `top` (the top is cut off).
std::vector<Vec3> BoxSides(double top, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3> cloud;
  for (int i = 0; i < 4000; ++i) {
    const double z = rng.Uniform() * top, t = rng.Uniform() * 0.32;
    cloud.push_back(t < 0.1    ? Vec3(t, 0, z)
                    : t < 0.16 ? Vec3(0.1, t - 0.1, z)
                    : t < 0.26 ? Vec3(0.26 - t, 0.06, z)
                               : Vec3(0, 0.32 - t, z));
  }
  return cloud;
}

TEST(RansacPlanes, ACutFindsTheRimWithTheCloudOnOneSide) {
  const double top = 0.15;
  const std::vector<Vec3> edges = BoxEdges(top, 1);
  const std::vector<Vec3> cloud = BoxSides(top, 2);
  RansacPlanesConfig config;
  RansacPlanes planes(edges, cloud, config, 60, std::nullopt);
  ASSERT_TRUE(planes.FindNext(RansacPlanes::Mode::kCut));
  const RansacPlane& first = planes.planes()[0];
  // The rim's plane: z = top, its 400 points (the edges' ends add a few).
  EXPECT_NEAR(std::abs(first.normal.z()), 1.0, 1e-3);
  EXPECT_NEAR(std::abs(first.offset), top, 1e-3);
  EXPECT_GE(first.inliers, 390);
  // Refitted on its inliers: the least-squares plane of the rim points.
  Vec3 n;
  double d;
  std::vector<int> all(edges.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  ASSERT_TRUE(
      FitPlaneOf(edges, PlaneInliers(edges, all, first.normal, first.offset, config.distance_m), &n, &d));
  EXPECT_NEAR(std::abs(n.dot(first.normal)), 1.0, 1e-9);
  EXPECT_FALSE(FitPlaneOf(edges, {0, 1}, &n, &d));
}

TEST(RansacPlanes, FreshPlanesTakeThePointsNoneExplainsYet) {
  // Two planes of points: x = 0 (600) and y = 0.2 (300), then no more.
  Rng rng(4);
  std::vector<Vec3> points;
  for (int i = 0; i < 600; ++i)
    points.emplace_back(0.0005 * (2 * rng.Uniform() - 1), 0.1 * rng.Uniform(), 0.1 * rng.Uniform());
  for (int i = 0; i < 300; ++i) points.emplace_back(0.1 + 0.1 * rng.Uniform(), 0.2, 0.1 * rng.Uniform());
  RansacPlanesConfig config;
  RansacPlanes planes(points, points, config, 100, std::nullopt);
  ASSERT_TRUE(planes.FindNext(RansacPlanes::Mode::kFresh));
  ASSERT_TRUE(planes.FindNext(RansacPlanes::Mode::kFresh));
  EXPECT_FALSE(planes.FindNext(RansacPlanes::Mode::kFresh));
  ASSERT_EQ(planes.planes().size(), 2u);
  EXPECT_NEAR(std::abs(planes.planes()[0].normal.x()), 1.0, 1e-3);
  EXPECT_EQ(planes.planes()[0].inliers, 600);
  EXPECT_NEAR(std::abs(planes.planes()[1].normal.y()), 1.0, 1e-3);
  EXPECT_EQ(planes.planes()[1].inliers, 300);
  // Seeded: the same planes again.
  RansacPlanes again(points, points, config, 100, std::nullopt);
  ASSERT_TRUE(again.FindNext(RansacPlanes::Mode::kFresh));
  EXPECT_EQ(again.planes()[0].normal, planes.planes()[0].normal);
  EXPECT_EQ(again.planes()[0].offset, planes.planes()[0].offset);
}

}  // namespace
}  // namespace graspfill::repair::geometry
