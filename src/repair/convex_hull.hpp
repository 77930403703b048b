// The 2D convex hull the virtual frame (the cloud's outline), the symmetry
// step, the claw-hole fills and the evidence's top (slab outlines) need,
// and tests against it. Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <vector>

namespace graspfill::repair {

/// Convex hull of `points` (sorted and deduplicated in place), counter-
/// clockwise, collinear points dropped (Andrew's monotone chain). Fewer
/// than 3 distinct points come back as they are.
inline std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d>* points) {
  std::vector<Eigen::Vector2d>& p = *points;
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i > 0; --i) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i - 1]) <= 0.0) --k;
    hull[k++] = p[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

/// How deep `p` lies inside the counter-clockwise convex polygon `hull`:
/// its distance to the nearest edge's line, negative outside; -infinity
/// for a hull of fewer than 3 points.
inline double DepthInsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p) {
  if (hull.size() < 3) return -std::numeric_limits<double>::infinity();
  double depth = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d edge = hull[(i + 1) % hull.size()] - a;
    const double length = edge.norm();
    if (!(length > 0.0)) continue;
    depth = std::min(depth, (edge.x() * (p.y() - a.y()) - edge.y() * (p.x() - a.x())) / length);
  }
  return depth;
}

/// Inside the counter-clockwise convex polygon `hull`, or on it.
inline bool InsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p) {
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    if ((b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) < 0.0) return false;
  }
  return true;
}

}  // namespace graspfill::repair
