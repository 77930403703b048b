// SPDX-License-Identifier: BSD-3-Clause
// Files for people and tools: object clouds as PLY (MeshLab, CloudCompare,
// Open3D) and triangle meshes (claw models, ground-truth objects).
//
// All functions are file I/O at the API boundary: they throw
// std::runtime_error naming the path (and strerror) on any failure. Writers
// write atomically (io/atomic_file.hpp): a failed write leaves an existing
// file as it was. They are reentrant
// (no shared state) and may be called from any thread.
#pragma once

#include <string>
#include <vector>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

/// Writes an object cloud as binary little-endian PLY.
///
/// Vertex properties, in this order: float x y z (gripper frame G, meters),
/// float nx ny nz (only if cloud.normals_G is non-empty), uchar provenance
/// (Provenance values; all kObserved if cloud.provenance is empty), float
/// confidence (only if cloud.confidence is non-empty), uchar red green blue
/// (the provenance's colour, core/provenance_colors.hpp, for viewers that
/// ignore `provenance`). The header carries the cloud's frame_name, utime,
/// seq and T_C_G as comments, read back by ReadCloudPly, and the software
/// version ("comment graspfill software graspfill X.Y.Z"). The same cloud
/// always gives the same bytes.
/// A cloud with zero points is written (a valid, empty PLY).
///
/// Written by hand rather than with Open3D's t::io::WritePointCloud: the
/// latter writes the uchar property correctly but refuses zero-point
/// clouds (Open3D 0.16) and gives no control over the header.
/// @param if_exists kFail: refuse to replace anything at `path` (see
///   io/atomic_file.hpp; a command without --force).
/// @throws std::runtime_error (with the path) if the file cannot be
///   written or normals/provenance are non-empty and not one per point.
void WriteCloudPly(const std::string& path, const ObjectCloud& cloud,
                   IfExists if_exists = IfExists::kReplace);

/// Reads a point cloud PLY (any PLY Open3D reads: ascii or binary, float or
/// double coordinates).
///
/// Normals are read if present. Provenance comes from a `provenance`
/// property if present (values must be 0..2), else every point is
/// kObserved (colours say nothing of it: they are ignored); confidence from a `confidence` property (values
/// in [0, 1]), else empty. frame_name, utime, seq and T_C_G come from WriteCloudPly's header comments if
/// present, else keep ObjectCloud's defaults. Holes and timings are not stored in PLY and come back empty.
/// @throws std::runtime_error (with the path) on a missing or malformed
///   file or out-of-range provenance.
ObjectCloud ReadCloudPly(const std::string& path);

/// The triangles of a PLY's faces over its vertices (ReadCloudPly's points,
/// same order): faces fan-triangulated, faces with a repeated index
/// dropped; empty when the file has no faces (a point cloud).
/// @throws std::runtime_error (with the path) as ReadCloudPly.
std::vector<Eigen::Vector3i> ReadPlyTriangles(const std::string& path);

/// Writes a triangle mesh as binary little-endian PLY (float x y z, faces as
/// `list uchar int vertex_indices`). Deterministic; an empty mesh is written.
/// @param if_exists as WriteCloudPly's.
/// @throws std::runtime_error (with the path) if the file cannot be written
///   or a triangle indexes a missing vertex.
void WriteMeshPly(const std::string& path, const TriangleMesh& mesh, IfExists if_exists = IfExists::kReplace);

/// Reads a triangle mesh from STL, OBJ or PLY (by extension, through
/// open3d::io::ReadTriangleMesh). Units are whatever the file uses; the
/// caller scales (graspfill expects meters).
/// @throws std::runtime_error (with the path) on a missing or unreadable
///   file, or a mesh with no triangles.
TriangleMesh ReadMesh(const std::string& path);

}  // namespace graspfill::io
