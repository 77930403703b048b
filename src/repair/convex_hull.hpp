// The 2D convex hull both the virtual frame (the cloud's outline) and the
// symmetry step (each slab's outline) need. Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <algorithm>
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

}  // namespace graspfill::repair
