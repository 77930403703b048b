// SPDX-License-Identifier: BSD-3-Clause
// A closed triangle mesh of an object cloud, for motion planners that take
// collision meshes (MoveIt, Drake, OMPL-based planners) rather than points.
//
// The surface is the zero set of a signed distance sampled on a regular grid
// around the cloud and triangulated by marching tetrahedra (each grid cube
// cut into six tetrahedra along its main diagonal). Near the cloud (the
// band) the distance is the mean of the k nearest points' plane distances
// n_i . (x - p_i); farther out only its sign matters, which a flood fill
// from the grid's border decides: outside where it reaches without coming
// within the wider fill band of a point (so that holes in the cloud up to
// twice that wide do not let it in), then grown back over that band's
// outer part a few steps. A piecewise-linear field on a consistent
// tetrahedral grid whose values are never zero has a zero set that is a
// closed 2-manifold without self-intersections: the mesh is watertight by
// construction, whatever the cloud. Triangles face outwards. Small closed
// pieces (skins around stray points) are dropped.
//
// Normals: the cloud's if it has them (one per point), else estimated from
// the nearest points and turned away from the centroid; either way each is
// turned to face the fill's outside where the grid tells the sides apart,
// so unoriented normals are fine.
#pragma once

#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// Parameters of BuildCollisionMesh. Defaults measured on the e2e shapes
/// (docs/collision-mesh.md; the numbers in
/// docs/measurements/2026-12-03-collision-mesh.md).
struct CollisionMeshConfig {
  /// Grid spacing [m]: the mesh's resolution. Triangles grow as
  /// (size / cell_m)^2; sharp edges round off within about one cell.
  double cell_m{0.002};
  /// Points whose plane distances are averaged at a grid node [count].
  int neighbors{8};
  /// Grid nodes within this many cells of a point get a distance [cells].
  double band_cells{2.5};
  /// The fill from the grid's border stops this many cells from the points:
  /// holes in the cloud up to twice as wide keep it outside [cells].
  double fill_band_cells{5.0};
  /// Closed pieces with fewer triangles than this fraction of the largest
  /// piece's are dropped (skins around stray points) [unitless, 0..1].
  double min_piece_fraction{0.05};
  /// Every point inside: the field is lowered around each point the
  /// surface would leave outside, just enough to take it in, so the mesh
  /// bulges only there (still watertight: any field's zero set is). Off,
  /// the surface follows the points' mean and about half lie outside.
  /// Points in a dropped piece stay outside.
  bool hold_points{false};

  /// @throws std::invalid_argument naming the field if out of range
  ///   (cell_m 0.0002..0.02 m, neighbors 1..64, band_cells 1.5..8,
  ///   fill_band_cells band_cells..12, min_piece_fraction 0..1).
  void Validate() const;
};

/// The closed, outward-facing triangle mesh of `cloud` (its points and
/// normals in G; provenance and the rest are not used). Deterministic: the
/// same cloud and config give the same mesh. Single-threaded apart from
/// Open3D's normal estimation (deterministic too).
/// @throws std::invalid_argument if the cloud has fewer than 4 points, a
///   non-finite point, or normals that are not one per point; or the
///   config is invalid; std::runtime_error if the grid would exceed
///   64 M nodes (cell_m too small for the cloud's extent).
TriangleMesh BuildCollisionMesh(const ObjectCloud& cloud, const CollisionMeshConfig& config);

}  // namespace graspfill::mesh
