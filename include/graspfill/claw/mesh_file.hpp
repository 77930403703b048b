// SPDX-License-Identifier: BSD-3-Clause
// Reads a claw link's mesh file: STL, OBJ, PLY, COLLADA (.dae) and the
// other formats assimp reads. One reader for every claw source (JSON
// descriptions and URDFs).
#pragma once

#include <cstdint>
#include <string>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/types.hpp"

namespace graspfill::claw {

/// The triangles of every mesh in the file, placed by the file's node
/// transforms, in the file's units converted to meters (COLLADA's <unit>),
/// and in a +z-up frame: a COLLADA file declaring Y_UP (or X_UP) is turned
/// so that its up axis is +z, Z_UP files are taken as they are (the URDF
/// convention). Vertices at the same position are merged (STL stores three
/// per triangle); points and lines are ignored. No other check: see
/// mesh_check.hpp. Throws std::runtime_error("<reason>: <path>...") when
/// the file is missing, not a regular file (a FIFO or device is refused
/// unopened), unreadable or holds no triangles, is larger than
/// kMaxMeshFileBytes or has more than `max_triangles` faces (the part of
/// kMaxClawTriangles the claw's other meshes leave; claw_limits.hpp),
/// counted before its vertices are merged.
TriangleMesh ReadMeshFile(const std::string& path, int64_t max_triangles = kMaxClawTriangles);

}  // namespace graspfill::claw
