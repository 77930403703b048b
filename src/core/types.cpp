// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/types.hpp"

namespace graspfill {

void TriangleMesh::Append(const TriangleMesh& other) {
  const int offset = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const Eigen::Vector3i& t : other.triangles) {
    triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  }
}

TriangleMesh TriangleMesh::Transformed(const Eigen::Isometry3d& T) const {
  TriangleMesh out;
  out.triangles = triangles;
  out.vertices.reserve(vertices.size());
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (const Eigen::Vector3f& v : vertices) out.vertices.push_back(Tf * v);
  return out;
}

bool SafeBound::Contains(const Eigen::Vector3f& p_G) const {
  if (empty() || !(voxel_m > 0.0f)) return false;
  const Eigen::Vector3f q = (p_G - origin_G) / voxel_m;
  if (!q.allFinite() || (q.array() < 0.0f).any()) return false;
  if (q.x() >= nx || q.y() >= ny || q.z() >= nz) return false;
  return Occupied(static_cast<int>(q.x()), static_cast<int>(q.y()), static_cast<int>(q.z()));
}

size_t SafeBound::count() const {
  size_t n = 0;
  for (uint8_t b : bits) n += static_cast<size_t>(__builtin_popcount(b));
  return n;
}

}  // namespace graspfill
