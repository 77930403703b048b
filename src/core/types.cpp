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

}  // namespace graspfill
