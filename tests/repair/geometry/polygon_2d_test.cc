// SPDX-License-Identifier: BSD-3-Clause
#include "geometry/polygon_2d.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "graspfill/core/random.hpp"

namespace graspfill::repair::geometry {
namespace {

using Vec2 = Eigen::Vector2d;

// Points filling a w x h rectangle turned by `angle` about `centre`.
std::vector<Vec2> TurnedRectangle(double w, double h, double angle, const Vec2& centre, int count) {
  Rng rng(5);
  const Vec2 a(std::cos(angle), std::sin(angle)), b(-a.y(), a.x());
  std::vector<Vec2> points;
  for (int i = 0; i < count; ++i) {
    points.push_back(centre + (rng.Uniform() - 0.5) * w * a + (rng.Uniform() - 0.5) * h * b);
  }
  for (const double sa : {-0.5, 0.5}) {
    for (const double sb : {-0.5, 0.5}) points.push_back(centre + sa * w * a + sb * h * b);
  }
  return points;
}

TEST(Polygon2d, HullOfASquareWithInnerAndCollinearPoints) {
  std::vector<Vec2> points = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0.2, 0.7}, {1, 1}};
  const std::vector<Vec2> hull = ConvexHull2d(&points);
  ASSERT_EQ(hull.size(), 4u);  // the inner, collinear and repeated points dropped
  EXPECT_DOUBLE_EQ(PolygonArea(hull), 1.0);
  // Counter-clockwise: the signed area is positive.
  double twice = 0.0;
  for (size_t i = 0; i < hull.size(); ++i) {
    twice += hull[i].x() * hull[(i + 1) % 4].y() - hull[i].y() * hull[(i + 1) % 4].x();
  }
  EXPECT_GT(twice, 0.0);
  EXPECT_TRUE(InsideConvex(hull, Vec2(0.5, 0.5)));
  EXPECT_TRUE(InsideConvex(hull, Vec2(1.0, 0.5)));  // on an edge
  EXPECT_FALSE(InsideConvex(hull, Vec2(1.01, 0.5)));
  EXPECT_NEAR(DepthInsideConvex(hull, Vec2(0.5, 0.3)), 0.3, 1e-12);
  EXPECT_NEAR(DepthInsideConvex(hull, Vec2(1.2, 0.5)), -0.2, 1e-12);
  const std::vector<Vec2> two = {{0, 0}, {1, 1}};
  EXPECT_EQ(DepthInsideConvex(two, Vec2(0.5, 0.5)), -std::numeric_limits<double>::infinity());
}

TEST(Polygon2d, AreaAndCentroidOfAnLShape) {
  // An L of two unit squares and one more: area 3, centroid off the corner.
  const std::vector<Vec2> l_shape = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_DOUBLE_EQ(PolygonArea(l_shape), 3.0);
  const Vec2 c = PolygonCentroid(l_shape);
  EXPECT_NEAR(c.x(), 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(c.y(), 5.0 / 6.0, 1e-12);
  // Clockwise: the same area and centroid.
  const std::vector<Vec2> reversed(l_shape.rbegin(), l_shape.rend());
  EXPECT_DOUBLE_EQ(PolygonArea(reversed), 3.0);
  EXPECT_NEAR((PolygonCentroid(reversed) - c).norm(), 0.0, 1e-12);
  // No area: the first vertex.
  const std::vector<Vec2> flat = {{1, 1}, {2, 2}, {3, 3}};
  EXPECT_EQ(PolygonCentroid(flat), Vec2(1, 1));
}

TEST(Polygon2d, TheMinimumAreaRectangleOfATurnedRectangle) {
  const Vec2 centre(0.3, -0.2);
  for (const double angle : {0.0, 0.4, 1.2, 2.5}) {
    const std::vector<Vec2> points = TurnedRectangle(0.12, 0.05, angle, centre, 3000);
    const Rect2 rect = MinAreaRect(ApproxHull2d(points, 32));
    // Along the long side (either way), centred.
    EXPECT_NEAR(std::abs(rect.axis.dot(Vec2(std::cos(angle), std::sin(angle)))), 1.0, 1e-3) << angle;
    EXPECT_NEAR((rect.centre - centre).norm(), 0.0, 1e-3) << angle;
  }
  // The approximate hull holds the extremes: every point inside it, or
  // within a column's width of it.
  const std::vector<Vec2> points = TurnedRectangle(0.12, 0.05, 0.7, centre, 3000);
  const std::vector<Vec2> hull = ApproxHull2d(points, 32);
  for (const Vec2& p : points) EXPECT_GT(DepthInsideConvex(hull, p), -0.13 / 32);
}

// The outline's description length: a noisy rectangle's hull comes down
// to its 4 corners; a circle's to about pi / sqrt(2 tolerance / r)
// vertices, more for a finer tolerance.
TEST(Polygon2d, SimplifiedVertexCountOfARectanglesHullAndACircle) {
  // A 50 x 35 mm rectangle's outline, each point moved up to 0.25 mm.
  Rng rng(8);
  std::vector<Vec2> points;
  for (int i = 0; i < 2000; ++i) {
    const double t = rng.Uniform() * 0.17, jitter_x = 0.0005 * (rng.Uniform() - 0.5),
                 jitter_y = 0.0005 * (rng.Uniform() - 0.5);
    const Vec2 on = t < 0.05    ? Vec2(t, 0.0)
                    : t < 0.085 ? Vec2(0.05, t - 0.05)
                    : t < 0.135 ? Vec2(0.135 - t, 0.035)
                                : Vec2(0.0, 0.17 - t);
    points.push_back(on + Vec2(jitter_x, jitter_y));
  }
  const std::vector<Vec2> hull = ConvexHull2d(&points);
  ASSERT_GT(hull.size(), 12u);  // the noise's vertices
  const int rectangle = SimplifiedVertexCount(hull, 0.0007);
  EXPECT_GE(rectangle, 4);
  EXPECT_LE(rectangle, 8);  // the corners, and a few the noise bevels
  std::vector<Vec2> circle;
  for (int i = 0; i < 400; ++i)
    circle.emplace_back(0.033 * std::cos(i * M_PI / 200), 0.033 * std::sin(i * M_PI / 200));
  const int coarse = SimplifiedVertexCount(circle, 0.0007), fine = SimplifiedVertexCount(circle, 0.0001);
  EXPECT_GE(coarse, 12);
  EXPECT_LE(coarse, 24);  // pi / sqrt(2 x 0.7 / 33) = 15
  EXPECT_GT(fine, 2 * coarse);
  EXPECT_EQ(SimplifiedVertexCount({Vec2(0, 0), Vec2(1, 0)}, 0.1), 2);
}

}  // namespace
}  // namespace graspfill::repair::geometry
