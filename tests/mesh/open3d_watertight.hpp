// SPDX-License-Identifier: BSD-3-Clause
// Open3D's watertightness test (closed, edge- and vertex-manifold, not
// self-intersecting) on a graspfill mesh, as the mesh tests, the e2e tests
// and mesh_containment check a mesh from outside the library.
#pragma once

#include <open3d/geometry/TriangleMesh.h>

#include "graspfill/types.hpp"

namespace graspfill::testing {

/// Open3D's IsWatertight of `m`. `merge_duplicates`: vertices at one
/// position merged first (an STL repeats each vertex per triangle).
inline bool Open3dWatertight(const TriangleMesh& m, bool merge_duplicates = false) {
  open3d::geometry::TriangleMesh o;
  o.vertices_.reserve(m.vertices.size());
  for (const Eigen::Vector3f& v : m.vertices) o.vertices_.push_back(v.cast<double>());
  o.triangles_ = m.triangles;
  if (merge_duplicates) o.RemoveDuplicatedVertices();
  return o.IsWatertight();
}

}  // namespace graspfill::testing
