// SPDX-License-Identifier: BSD-3-Clause
// Checks on claw meshes before they reach the ray caster: a bad index or a
// NaN vertex from a user's mesh file must be an error at load, naming the
// file and link, not a failure at the first gripper state.
#pragma once

#include <string>

#include "graspfill/types.hpp"

namespace graspfill::claw {

/// What makes `mesh` unusable, or "" when it is fine: a triangle index out
/// of range (negative or >= the vertex count) or a non-finite vertex used
/// by a triangle. The text names the first offender, e.g. "triangle 3
/// index 1000000 out of range (12 vertices)".
std::string MeshDefect(const TriangleMesh& mesh);

/// Removes zero-area triangles (a repeated index, or an area below
/// `min_area_m2`): they cover no pixel but count as faces. Returns how many
/// were removed; vertices are kept.
int DropDegenerateTriangles(TriangleMesh* mesh, double min_area_m2 = 1e-14);

}  // namespace graspfill::claw
