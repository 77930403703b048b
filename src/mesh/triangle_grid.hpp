// SPDX-License-Identifier: BSD-3-Clause
// A uniform grid over triangles' bounding boxes, for triangles that move:
// which triangles lie near a box, in about constant time per cell.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace graspfill::mesh {

class TriangleGrid {
 public:
  /// `count` triangle ids (0..count-1), cells `cell_m` on a side [m].
  TriangleGrid(int count, double cell_m);

  /// Files triangle `id` under `box`, replacing where it was filed before.
  void Place(int id, const Eigen::AlignedBox3d& box);
  /// Takes triangle `id` out (a no-op if it is not filed).
  void Remove(int id);
  /// The filed triangles whose box overlaps `box`, each once, in no set
  /// order: into `out` (cleared first).
  void Near(const Eigen::AlignedBox3d& box, std::vector<int>* out);

 private:
  struct CellRange {
    Eigen::Vector3i low{0, 0, 0};
    Eigen::Vector3i high{-1, -1, -1};  // empty: not filed
  };
  CellRange RangeOf(const Eigen::AlignedBox3d& box) const;
  static uint64_t Key(int x, int y, int z);

  double cell_m_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
  std::vector<CellRange> filed_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::vector<uint32_t> seen_;  // query stamp per id: each reported once
  uint32_t query_{0};
};

}  // namespace graspfill::mesh
