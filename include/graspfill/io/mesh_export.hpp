// SPDX-License-Identifier: BSD-3-Clause
// Triangle meshes for planners and CAD tools, in the format a file's
// extension names: .ply (binary PLY), .stl (binary STL), .obj (Wavefront).
//
// File I/O at the API boundary: throws std::runtime_error naming the path.
// Writes atomically (io/atomic_file.hpp); reentrant, any thread.
#pragma once

#include <optional>
#include <string>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

enum class MeshFormat { kPly, kStl, kObj };

/// The format `path`'s extension names (case-insensitive), or none for any
/// other extension.
std::optional<MeshFormat> MeshFormatOf(const std::string& path);

/// Writes `mesh` to `path` in the format of its extension, vertex positions
/// as 32-bit floats in the mesh's frame and unit (graspfill: meters). The
/// same mesh always gives the same bytes. STL stores each triangle's unit
/// normal (from its winding; zero for a degenerate triangle) and an 80-byte
/// header naming graspfill; OBJ writes `v` and `f` lines (1-based indices)
/// with nine significant digits; PLY is WriteMeshPly's.
/// @param if_exists kFail: refuse to replace anything at `path` (see
///   io/atomic_file.hpp; a command without --force).
/// @throws std::runtime_error (with the path) on an unknown extension, a
///   triangle that indexes a missing vertex, or a failed write.
void WriteMesh(const std::string& path, const TriangleMesh& mesh, IfExists if_exists = IfExists::kReplace);

}  // namespace graspfill::io
