// SPDX-License-Identifier: BSD-3-Clause
// The parts of a replayed cloud: the fused points (provenance observed) and
// the points the hole repair added after them.
#pragma once

#include <algorithm>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::testing {

/// The points fused from depth frames, in order. Checks about the fusion use
/// these only, so that they pin the fusion and not the repair.
inline std::vector<Eigen::Vector3f> ObservedPoints(const ObjectCloud& cloud) {
  std::vector<Eigen::Vector3f> observed;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.provenance.empty() || cloud.provenance[i] == Provenance::kObserved) {
      observed.push_back(cloud.points_G[i]);
    }
  }
  return observed;
}

/// Dense points on a mesh's triangles, about `spacing_m` apart (a few per
/// mm^2 is plenty to tell claw points from object points).
inline std::vector<Eigen::Vector3f> SampleSurface(const TriangleMesh& mesh, float spacing_m) {
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const int n = std::max(1, static_cast<int>(std::max((b - a).norm(), (c - a).norm()) / spacing_m));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
        points.push_back(a + u * (b - a) + v * (c - a));
      }
    }
  }
  return points;
}

}  // namespace graspfill::testing
