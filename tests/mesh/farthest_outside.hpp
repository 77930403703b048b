// SPDX-License-Identifier: BSD-3-Clause
// How far points lie outside a closed mesh, by the tests' own means (not
// mesh::OutsideDistances, the code under test): the generalized winding
// number says outside, brute-force point-triangle distances say how far.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/types.hpp"

namespace graspfill::testing {

/// The farthest of `points` (every `stride`-th) outside `m` [m]; 0 when
/// all are inside.
inline double FarthestOutside(const TriangleMesh& m, const std::vector<Eigen::Vector3f>& points,
                              size_t stride = 1) {
  double worst = 0.0;
  for (size_t i = 0; i < points.size(); i += stride) {
    const Eigen::Vector3d p = points[i].cast<double>();
    if (mesh::WindingNumber(m, p) > 0.5) continue;
    double d = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& t : m.triangles) {
      d = std::min(
          d, mesh::PointTriangleDistance(p, m.vertices[t[0]].cast<double>(), m.vertices[t[1]].cast<double>(),
                                         m.vertices[t[2]].cast<double>()));
    }
    worst = std::max(worst, d);
  }
  return worst;
}

}  // namespace graspfill::testing
