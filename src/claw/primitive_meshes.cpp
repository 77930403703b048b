// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/primitive_meshes.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace graspfill::claw {
namespace {

// A ring of vertices at height z, radius r; returns the first index.
int AddRing(TriangleMesh* mesh, double r, double z, int segments) {
  const int first = static_cast<int>(mesh->vertices.size());
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * M_PI * i / segments;
    mesh->vertices.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                                static_cast<float>(z));
  }
  return first;
}

// Quads between two rings (lower ring `a`, upper ring `b`), outward.
void Band(TriangleMesh* mesh, int a, int b, int segments) {
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    mesh->triangles.emplace_back(a + i, a + j, b + j);
    mesh->triangles.emplace_back(a + i, b + j, b + i);
  }
}

// A fan from `centre` to a ring; `up` faces +z when true.
void Cap(TriangleMesh* mesh, int centre, int ring, int segments, bool up) {
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    if (up) {
      mesh->triangles.emplace_back(centre, ring + i, ring + j);
    } else {
      mesh->triangles.emplace_back(centre, ring + j, ring + i);
    }
  }
}

}  // namespace

TriangleMesh BoxMesh(const Eigen::Vector3d& size_m) {
  const Eigen::Vector3f hi = (0.5 * size_m).cast<float>();
  const Eigen::Vector3f lo = -hi;
  TriangleMesh box;
  for (int i = 0; i < 8; ++i) {
    box.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                              (i & 4) ? hi.z() : lo.z());
  }
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    box.triangles.emplace_back(q[0], q[1], q[2]);
    box.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return box;
}

TriangleMesh CylinderMesh(double radius_m, double length_m, int segments) {
  TriangleMesh mesh;
  const int bottom = AddRing(&mesh, radius_m, -0.5 * length_m, segments);
  const int top = AddRing(&mesh, radius_m, 0.5 * length_m, segments);
  Band(&mesh, bottom, top, segments);
  const int bottom_centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(-0.5 * length_m));
  const int top_centre = bottom_centre + 1;
  mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(0.5 * length_m));
  Cap(&mesh, bottom_centre, bottom, segments, false);
  Cap(&mesh, top_centre, top, segments, true);
  return mesh;
}

TriangleMesh SphereMesh(double radius_m, int segments) {
  TriangleMesh mesh;
  const int bands = std::max(2, segments / 2);
  std::vector<int> rings;
  for (int k = 1; k < bands; ++k) {
    const double polar = M_PI * k / bands;  // from the south pole up
    rings.push_back(AddRing(&mesh, radius_m * std::sin(polar), -radius_m * std::cos(polar), segments));
  }
  for (size_t k = 0; k + 1 < rings.size(); ++k) Band(&mesh, rings[k], rings[k + 1], segments);
  const int south = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(-radius_m));
  const int north = south + 1;
  mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(radius_m));
  Cap(&mesh, south, rings.front(), segments, false);
  Cap(&mesh, north, rings.back(), segments, true);
  return mesh;
}

}  // namespace graspfill::claw
