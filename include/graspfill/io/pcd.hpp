// SPDX-License-Identifier: BSD-3-Clause
// Object clouds as PCD, the Point Cloud Library's format (PCL tools,
// Open3D, planners built on PCL). File I/O at the API boundary: throws
// std::runtime_error naming the path; reentrant.
#pragma once

#include <string>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

/// Writes an object cloud as binary PCD v0.7 (little-endian, as PCL and
/// Open3D read it).
///
/// Fields, in this order: float x y z (gripper frame G, meters), float
/// normal_x normal_y normal_z (only if cloud.normals_G is non-empty), rgb
/// (the provenance's colour packed as PCL packs it, 0x00RRGGBB in a 4-byte
/// float field), uint8 provenance (0 observed, 1 surface, 2 symmetry), float
/// confidence (only if cloud.confidence is non-empty). VIEWPOINT is the
/// camera's pose in G (T_G_C, the inverse of cloud.T_C_G), which PCL uses to
/// orient normals. Header comments ("# graspfill <key> <value>") carry the
/// frame name, utime, seq, T_C_G and the software version, as the PLY's do.
/// The same cloud always gives the same bytes. A cloud with no points is
/// written (POINTS 0, as the format allows), though Open3D 0.16's readers
/// refuse such a file.
///
/// Written by hand, as the PLY is: Open3D 0.16's t::io::WritePointCloud
/// writes custom fields but refuses a cloud with no points, always writes
/// an identity VIEWPOINT, and writes in place rather than atomically.
/// @param if_exists as WriteCloudPly's (io/ply.hpp).
/// @throws std::runtime_error (with the path) if the file cannot be
///   written, or normals, provenance or confidence are given but not one
///   per point.
void WriteCloudPcd(const std::string& path, const ObjectCloud& cloud,
                   IfExists if_exists = IfExists::kReplace);

}  // namespace graspfill::io
