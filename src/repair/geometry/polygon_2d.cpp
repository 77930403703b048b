// SPDX-License-Identifier: BSD-3-Clause
#include "polygon_2d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace graspfill::repair::geometry {

std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d>* points) {
  std::vector<Eigen::Vector2d>& p = *points;
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
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

std::vector<Eigen::Vector2d> ApproxHull2d(const std::vector<Eigen::Vector2d>& q, int columns) {
  double x_lo = q[0].x(), x_hi = q[0].x();
  size_t i_lo = 0, i_hi = 0;
  for (size_t i = 1; i < q.size(); ++i) {
    if (q[i].x() < x_lo) x_lo = q[i].x(), i_lo = i;
    if (q[i].x() > x_hi) x_hi = q[i].x(), i_hi = i;
  }
  const double width = std::max(x_hi - x_lo, 1e-12);
  std::vector<int> lowest(static_cast<size_t>(columns), -1), highest(static_cast<size_t>(columns), -1);
  for (size_t i = 0; i < q.size(); ++i) {
    const int c = std::min(columns - 1, static_cast<int>((q[i].x() - x_lo) / width * columns));
    int& lo = lowest[static_cast<size_t>(c)];
    int& hi = highest[static_cast<size_t>(c)];
    if (lo < 0 || q[i].y() < q[static_cast<size_t>(lo)].y()) lo = static_cast<int>(i);
    if (hi < 0 || q[i].y() > q[static_cast<size_t>(hi)].y()) hi = static_cast<int>(i);
  }
  std::vector<Eigen::Vector2d> pts = {q[i_lo], q[i_hi]};
  for (int c = 0; c < columns; ++c) {
    if (lowest[static_cast<size_t>(c)] >= 0)
      pts.push_back(q[static_cast<size_t>(lowest[static_cast<size_t>(c)])]);
    if (highest[static_cast<size_t>(c)] >= 0)
      pts.push_back(q[static_cast<size_t>(highest[static_cast<size_t>(c)])]);
  }
  return ConvexHull2d(&pts);
}

double DepthInsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p) {
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

bool InsideConvex(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p) {
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    if ((b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) < 0.0) return false;
  }
  return true;
}

int SimplifiedVertexCount(const std::vector<Eigen::Vector2d>& polygon, double tolerance) {
  const size_t n = polygon.size();
  if (n < 3) return static_cast<int>(n);
  // Split at the vertex farthest from the first: both ends are kept.
  size_t far = 0;
  for (size_t i = 1; i < n; ++i) {
    if ((polygon[i] - polygon[0]).squaredNorm() > (polygon[far] - polygon[0]).squaredNorm()) far = i;
  }
  if (far == 0) return 1;
  // Chains (from, to) walking forward, ends kept; a stack, not recursion:
  // a hull can have as many vertices as the cloud has points.
  int kept = 2;
  std::vector<std::pair<size_t, size_t>> chains = {{0, far}, {far, 0}};
  while (!chains.empty()) {
    const auto [from, to] = chains.back();
    chains.pop_back();
    const Eigen::Vector2d a = polygon[from], chord = polygon[to] - a;
    const double length = chord.norm();
    double farthest = -1.0;
    size_t at = from;
    for (size_t i = (from + 1) % n; i != to; i = (i + 1) % n) {
      const Eigen::Vector2d v = polygon[i] - a;
      const double d = length > 0.0 ? std::abs(chord.x() * v.y() - chord.y() * v.x()) / length : v.norm();
      if (d > farthest) farthest = d, at = i;
    }
    if (!(farthest > tolerance)) continue;
    ++kept;
    chains.emplace_back(from, at);
    chains.emplace_back(at, to);
  }
  return kept;
}

double PolygonArea(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * std::abs(twice);
}

Eigen::Vector2d PolygonCentroid(const std::vector<Eigen::Vector2d>& polygon) {
  double a = 0.0;
  Eigen::Vector2d c(0, 0);
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& p = polygon[i];
    const Eigen::Vector2d& q = polygon[(i + 1) % polygon.size()];
    const double w = p.x() * q.y() - q.x() * p.y();
    a += w;
    c += w * (p + q);
  }
  return std::abs(a) > 0.0 ? Eigen::Vector2d(c / (3.0 * a)) : polygon.front();
}

Rect2 MinAreaRect(const std::vector<Eigen::Vector2d>& hull) {
  std::vector<Eigen::Vector2d> dirs;
  const size_t h = hull.size();
  const size_t edges = h >= 3 ? h : (h == 2 ? 1 : 0);
  for (size_t i = 0; i < edges; ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % h] - hull[i];
    if (e.norm() > 0) dirs.push_back(e.normalized());
  }
  if (dirs.empty()) dirs.push_back(Eigen::Vector2d(1, 0));
  double best_area = std::numeric_limits<double>::infinity();
  Rect2 best;
  for (const Eigen::Vector2d& e : dirs) {
    const Eigen::Vector2d n(-e.y(), e.x());
    double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
    for (const Eigen::Vector2d& p : hull) {
      a0 = std::min(a0, e.dot(p)), a1 = std::max(a1, e.dot(p));
      b0 = std::min(b0, n.dot(p)), b1 = std::max(b1, n.dot(p));
    }
    const double area = (a1 - a0) * (b1 - b0);
    if (area < best_area) {
      best_area = area;
      best.centre = 0.5 * (a0 + a1) * e + 0.5 * (b0 + b1) * n;
      best.axis = (a1 - a0) >= (b1 - b0) ? e : n;
    }
  }
  return best;
}

}  // namespace graspfill::repair::geometry
