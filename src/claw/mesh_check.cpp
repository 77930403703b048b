// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/mesh_check.hpp"

#include <algorithm>

namespace graspfill::claw {

std::string MeshDefect(const TriangleMesh& mesh) {
  const long long num_vertices = static_cast<long long>(mesh.vertices.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const long long index = mesh.triangles[t][k];
      if (index < 0 || index >= num_vertices) {
        return "triangle " + std::to_string(t) + " index " + std::to_string(index) + " out of range (" +
               std::to_string(num_vertices) + " vertices)";
      }
      if (!mesh.vertices[index].allFinite()) {
        return "vertex " + std::to_string(index) + " (of triangle " + std::to_string(t) + ") is not finite";
      }
    }
  }
  return "";
}

int DropDegenerateTriangles(TriangleMesh* mesh, double min_area_m2) {
  const auto degenerate = [&](const Eigen::Vector3i& t) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
    const Eigen::Vector3d a = mesh->vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh->vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh->vertices[t[2]].cast<double>();
    return !(0.5 * (b - a).cross(c - a).norm() >= min_area_m2);
  };
  const size_t before = mesh->triangles.size();
  mesh->triangles.erase(std::remove_if(mesh->triangles.begin(), mesh->triangles.end(), degenerate),
                        mesh->triangles.end());
  return static_cast<int>(before - mesh->triangles.size());
}

}  // namespace graspfill::claw
