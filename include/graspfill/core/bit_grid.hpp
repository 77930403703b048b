// SPDX-License-Identifier: BSD-3-Clause
// A dense grid of one bit per cell over a box: which cells hold something.
// Built for change tests between two clouds of the same object (a few
// hundred thousand cells, one bit each): a lookup is an index and a shift,
// and Reset keeps the storage for the next build.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace graspfill {

class BitGrid {
 public:
  /// Covers `box` with cubic cells of `cell_m` [m]. Throws
  /// std::invalid_argument on an empty box, a cell <= 0, or more than
  /// `max_cells` cells (the box is too large for the cell).
  void Reset(const Eigen::AlignedBox3f& box, float cell_m, size_t max_cells = 64u << 20);

  /// Sets the cell holding `p` (and, with `dilate`, the 26 around it);
  /// points outside the box are ignored.
  void Set(const Eigen::Vector3f& p, bool dilate = false);
  /// Whether the cell holding `p` is set; false outside the box.
  bool Test(const Eigen::Vector3f& p) const;

  size_t cells() const { return static_cast<size_t>(nx_) * ny_ * nz_; }
  bool empty() const { return words_.empty(); }

 private:
  // The cell of `p`, or false outside.
  bool CellOf(const Eigen::Vector3f& p, int* i, int* j, int* k) const;
  void SetCell(int i, int j, int k);

  Eigen::Vector3f origin_{0, 0, 0};
  float inv_cell_{0.0f};
  int nx_{0}, ny_{0}, nz_{0};
  std::vector<uint64_t> words_;
};

}  // namespace graspfill
