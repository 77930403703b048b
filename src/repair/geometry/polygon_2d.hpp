// SPDX-License-Identifier: BSD-3-Clause
// The repair's 2D geometry: convex hulls (the cloud's outline for the
// virtual frame, the slab outlines of the symmetry step, the claw fills and
// the evidence's top), tests against them, polygon area and centroid, and
// the minimum-area rectangle. Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace graspfill::repair::geometry {

/// Convex hull of `points` (sorted and deduplicated in place), counter-
/// clockwise, collinear points dropped (Andrew's monotone chain). Fewer
/// than 3 distinct points come back as they are.
std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d>* points);

/// Convex hull (counter-clockwise) of the lowest and highest point of each
/// of `columns` x-columns of `q` (not empty) plus the x extremes: O(n)
/// instead of sorting every point, exact to within a column's width.
std::vector<Eigen::Vector2d> ApproxHull2d(const std::vector<Eigen::Vector2d>& q, int columns);

/// How deep `p` lies inside the counter-clockwise convex polygon `hull`:
/// its distance to the nearest edge's line, negative outside; -infinity
/// for a hull of fewer than 3 points.
double DepthInsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p);

/// Inside the counter-clockwise convex polygon `hull`, or on it.
bool InsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p);

/// Area of a simple polygon (the shoelace formula), either orientation.
double PolygonArea(const std::vector<Eigen::Vector2d>& polygon);

/// Centroid of the area of a simple polygon; its first vertex when the
/// area is 0.
Eigen::Vector2d PolygonCentroid(const std::vector<Eigen::Vector2d>& polygon);

/// How many of the closed `polygon`'s vertices describe it to within
/// `tolerance` (Douglas-Peucker: a vertex is kept where the chord between
/// its kept neighbours passes farther from some vertex than that): a
/// noisy rectangle's hull needs 4, a circle of radius r about
/// pi / sqrt(2 tolerance / r). The polygon itself when under 3 vertices.
int SimplifiedVertexCount(const std::vector<Eigen::Vector2d>& polygon, double tolerance);

/// A rectangle's centre and the direction of its longer side.
struct Rect2 {
  Eigen::Vector2d axis{1, 0};  ///< unit
  Eigen::Vector2d centre{0, 0};
};

/// Minimum-area rectangle around the convex polygon `hull`: one of its
/// sides lies on a hull edge (the theorem behind rotating calipers), and
/// every edge direction is tried (O(h^2): meant for the few dozen points
/// of ApproxHull2d).
Rect2 MinAreaRect(const std::vector<Eigen::Vector2d>& hull);

}  // namespace graspfill::repair::geometry
