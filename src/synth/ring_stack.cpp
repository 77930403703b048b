// SPDX-License-Identifier: BSD-3-Clause
#include "synth/internal/ring_stack.hpp"

#include <array>
#include <map>
#include <stdexcept>

namespace graspfill::synth::internal {
namespace {

bool IsPole(const Ring& ring) {
  for (const Eigen::Vector3d& p : ring) {
    if (p.cast<float>() != ring.front().cast<float>()) return false;
  }
  return true;
}

}  // namespace

TriangleMesh RingStackMesh(const std::vector<Ring>& rings) {
  if (rings.size() < 3) throw std::invalid_argument("RingStackMesh: fewer than 3 rings");
  const size_t n = rings.front().size();
  for (const Ring& ring : rings) {
    if (ring.size() != n || n < 3) {
      throw std::invalid_argument("RingStackMesh: rings need the same size, at least 3");
    }
  }
  if (!IsPole(rings.front()) || !IsPole(rings.back())) {
    throw std::invalid_argument("RingStackMesh: the first and last rings must be poles");
  }

  // Merge on the float coordinates the mesh stores, so that equal points
  // become one vertex however they were computed in double.
  TriangleMesh mesh;
  std::map<std::array<float, 3>, int> index_of;
  std::vector<std::vector<int>> index(rings.size(), std::vector<int>(n));
  for (size_t k = 0; k < rings.size(); ++k) {
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f p = rings[k][i].cast<float>();
      const auto [it, inserted] =
          index_of.emplace(std::array<float, 3>{p.x(), p.y(), p.z()}, static_cast<int>(mesh.vertices.size()));
      if (inserted) mesh.vertices.push_back(p);
      index[k][i] = it->second;
    }
  }

  auto add = [&mesh](int a, int b, int c) {
    if (a != b && b != c && c != a) mesh.triangles.emplace_back(a, b, c);
  };
  for (size_t k = 0; k + 1 < rings.size(); ++k) {
    for (size_t i = 0; i < n; ++i) {
      const size_t j = (i + 1) % n;
      // Lower a -> b along the ring, upper d -> c: (a, b, c) faces out.
      const int a = index[k][i];
      const int b = index[k][j];
      const int c = index[k + 1][j];
      const int d = index[k + 1][i];
      add(a, b, c);
      add(a, c, d);
    }
  }
  return mesh;
}

}  // namespace graspfill::synth::internal
