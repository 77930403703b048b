// SPDX-License-Identifier: BSD-3-Clause
// Meshing of a stack of closed loops ("rings"), the common skeleton of the
// zoo's bodies of revolution, swept tubes and star-shaped blobs. Not part
// of the public API: the shapes reach callers through MakeShape.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::synth::internal {

/// One ring: `n` points [m] in order. A ring whose points are all equal is
/// a pole; a ring may also be partly collapsed (runs of equal points).
using Ring = std::vector<Eigen::Vector3d>;

/// Closed, consistently oriented mesh joining ring k to ring k + 1 by quads
/// (two triangles each).
///
/// Orientation: every ring runs counter-clockwise about the stack's
/// direction (from the first ring towards the last, right-hand rule), like
/// a horizontal circle seen from +z in a stack going up; the triangles then
/// face outwards.
///
/// Points that are bit-identical once stored as float are merged and the
/// triangles that thereby lose a corner are dropped, which is how poles and
/// collapsed runs (a rounded box's flat faces) close the surface. Callers
/// must build such points exactly equal, e.g. a pole as `n` copies of one
/// point. Distinct points must stay distinct in float.
///
/// @param rings at least 3 rings of the same size n >= 3; the first and
///        the last must be poles.
/// @throws std::invalid_argument on fewer rings, unequal sizes or a first
///         or last ring that is not a pole.
TriangleMesh RingStackMesh(const std::vector<Ring>& rings);

}  // namespace graspfill::synth::internal
