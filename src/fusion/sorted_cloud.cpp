// SPDX-License-Identifier: BSD-3-Clause
#include "sorted_cloud.hpp"

#include <algorithm>
#include <numeric>

namespace graspfill::fusion {

void WriteSortedCloud(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                      ObjectCloud* cloud) {
  auto less = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    if (a.x() != b.x()) return a.x() < b.x();
    if (a.y() != b.y()) return a.y() < b.y();
    return a.z() < b.z();
  };
  const size_t n = points.size();
  const bool has_normals = normals.size() == n && n > 0;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (points[a] != points[b]) return less(points[a], points[b]);
    return has_normals && less(normals[a], normals[b]);
  });
  cloud->points_G.resize(n);
  cloud->normals_G.resize(has_normals ? n : 0);
  cloud->provenance.assign(n, Provenance::kObserved);
  for (size_t i = 0; i < n; ++i) {
    cloud->points_G[i] = points[order[i]].cast<float>();
    if (has_normals) cloud->normals_G[i] = normals[order[i]].normalized().cast<float>();
  }
}

}  // namespace graspfill::fusion
