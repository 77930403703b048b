// SPDX-License-Identifier: BSD-3-Clause
// Decimation that never cuts into the solid: a closed mesh brought down to
// a triangle budget by edge collapses, each of which keeps the mesh a
// closed 2-manifold and moves the surface only outwards, so the result
// contains the input (a progressive hull: Sander, Gu, Gortler, Hoppe and
// Snyder, "Silhouette clipping", SIGGRAPH 2000).
//
// - Topology: an edge (a, b) collapses only if a and b share exactly the
//   two neighbours opposite the edge (the link condition of Dey et al.),
//   which keeps a closed 2-manifold closed and manifold.
// - Outwards: the new vertex lies on or outside the plane of every
//   triangle around a and b. Then every old triangle lies inside the new
//   fan's cone, and the new solid holds the old one.
// - Where: of three places, the feasible one with the least quadric error
//   (Garland and Heckbert: squared distances to the original planes
//   around the merged vertices): the quadric's optimum moved onto the
//   feasible side by at most three plane projections, and the edge's two
//   ends. The cheapest collapse goes first.
// - No fold, no crossing: a collapse is refused if any triangle around it
//   would turn over (its normal by more than 90 degrees) or become
//   degenerate, or if the new fan would cross another triangle (two sheets
//   of a thin wall growing into each other).
#pragma once

#include "graspfill/types.hpp"

namespace graspfill::mesh {

struct OutwardDecimation {
  TriangleMesh mesh;  ///< outward-facing, closed; its vertices renumbered
  /// Edge collapses done [count].
  int collapses{0};
  /// Whether max_triangles was reached; false when no allowed collapse was
  /// left first (the mesh is then as small as the rules allow).
  bool reached_budget{false};
};

/// Decimates `closed_mesh` (a closed 2-manifold with outward triangles, as
/// BuildCollisionMesh makes) to at most `max_triangles` triangles, or as
/// close as the rules above allow. Deterministic. The input's unused
/// vertices are dropped.
/// @throws std::invalid_argument if `closed_mesh` has an edge not shared by
///   exactly two triangles in opposite directions, a bad index, or
///   max_triangles < 4.
OutwardDecimation DecimateOutward(const TriangleMesh& closed_mesh, int max_triangles);

}  // namespace graspfill::mesh
