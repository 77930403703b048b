// SPDX-License-Identifier: BSD-3-Clause
// The benchmark's "Poisson-only" baseline (graspfill bench repair): every
// hole, claw holes and the missing top alike, filled from one screened
// Poisson surface (Open3D) of the whole cloud. A reference for the
// repair's numbers, not part of the product library (graspfill::repair);
// built into the CLI's benchmark and the tests only.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// Settings of the Poisson-only baseline.
struct PoissonFillConfig {
  /// Octree depth: 7 gives ~2.2 mm cells on a 14 cm object at scale 2.
  int poisson_depth{7};
  /// Ratio of the reconstruction cube to the cloud's bounding cube. At
  /// Open3D's 1.1 the surface of an open-topped cloud leaves the cube
  /// through the opening and never closes the top; at 2 it closes it with
  /// a dome (measured on the protocol's cylinder).
  double poisson_scale{2.0};
  /// Neighbours of the PCA normal estimate when no normals are given.
  int normal_knn{16};
  /// Mesh vertices with a Poisson density below this quantile of all the
  /// densities are trimmed with their triangles (the surface Poisson
  /// invents far from any point). 0 (the default) keeps everything: the
  /// least supported part of the mesh is exactly the fill of the missing
  /// top (densities ~4-5 there against a median of ~7.8 on the cylinder).
  double density_trim_quantile{0.0};
  /// The mesh is cropped to the cloud's bounding box padded by this
  /// fraction of the box's largest edge (room for the dome over the top).
  double crop_pad_fraction{0.1};
  /// A mesh sample is added only where no cloud point lies within this
  /// many D.
  double min_gap_d{2.0};
  /// Fill density relative to the cloud's surface density.
  double fill_density_factor{1.0};
  uint64_t seed{11};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// The benchmark's baseline: one Poisson surface of the whole cloud (any
/// frame, no hole boundaries), density-trimmed and cropped, sampled where
/// the cloud has no point within `min_gap_d` D. Fills claw holes and the
/// missing top alike.
/// @param points the cloud [m], finite coordinates.
/// @param normals optional outward unit normals; when null, PCA normals
///        oriented away from the centroid.
/// @param index optional neighbour index over `points` (same vector).
/// @return the new points, in the frame of `points`.
/// @throws std::invalid_argument as RepairClawHoles.
PointList PoissonFillAll(const PointList& points, const PoissonFillConfig& config,
                         const std::vector<Eigen::Vector3f>* normals = nullptr,
                         const NeighborIndex* index = nullptr);

}  // namespace graspfill::repair
