// SPDX-License-Identifier: BSD-3-Clause
// A closest-point table for point-to-plane ICP: per cell of a grid around a
// model's points, the index of the point nearest the cell's centre within
// a band. Built once per model, looked up once per match, so that an
// iteration costs no tree search (the claw registration's model, the
// object tracker's model).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace graspfill::refine {

class ClosestPointGrid {
 public:
  /// Over every `stride`-th of `points` (at least one), with cells of
  /// `cell_m` [m] and the table reaching `band_m` [m] beyond all of them.
  /// Reuses the memory of the last build; no points give an empty table.
  void Build(const std::vector<Eigen::Vector3f>& points, int stride, double cell_m, double band_m);
  /// Forgets the table (every lookup then finds nothing).
  void Clear();
  /// Index into the points of the one nearest the centre of p's cell; -1
  /// when none is within the band or p is off the table.
  int Nearest(const Eigen::Vector3f& p) const;
  /// The centre of p's cell (the point Nearest answers for).
  Eigen::Vector3f CellCentre(const Eigen::Vector3f& p) const;

 private:
  Eigen::Vector3f origin_{0, 0, 0};
  float cell_{1.0f};
  int nx_{0}, ny_{0}, nz_{0};
  std::vector<int32_t> nearest_;  // -1: no point within the band
  std::vector<float> best_d2_;    // building scratch
  std::vector<int> row_reach_;    // building scratch: per row offset, the widest cell offset
};

}  // namespace graspfill::refine
