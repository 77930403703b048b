// SPDX-License-Identifier: BSD-3-Clause
// The collision mesh as carried by collision_mesh_t (lcmtypes/
// collision_mesh_t.lcm), on its own channel (ChannelNames::collision_mesh),
// so that a planner adds it as a collision object without reading files.
// Pure functions over bytes, with messages.hpp's error policy: the decoder
// never throws on bad input, the encoder only on caller misuse.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

/// Most vertices, and most triangles, a collision_mesh_t may carry
/// [count]: 16 M (200 MB of triangles), far beyond any planner's mesh; the
/// decoder refuses more before it allocates.
constexpr int32_t kMaxCollisionMeshElements = int32_t{1} << 24;

/// One collision mesh, as collision_mesh_t carries it.
struct CollisionMeshMessage {
  int64_t utime{0};     ///< the model's newest depth frame [us]
  int64_t seq{0};       ///< the model's object_cloud_t.seq
  int64_t grasp_id{0};  ///< 0 = not numbered
  std::string frame_name{"gripper"};
  /// Pose of G in C at utime.
  Eigen::Isometry3d T_C_G{Eigen::Isometry3d::Identity()};
  /// Outward-facing triangles, vertices in G [m].
  TriangleMesh mesh;
  CollisionMeshKind kind{CollisionMeshKind::kDecimated};
  bool watertight{false};
  /// The farthest cloud point outside the mesh [m].
  double deviation_m{0.0};
};

/// Encodes `message` as collision_mesh_t (the quaternion normalized).
/// @throws std::invalid_argument on a triangle index outside the vertices,
///   more than kMaxCollisionMeshElements vertices or triangles, a
///   non-finite vertex, pose or deviation, a negative deviation, or a
///   frame name with a NUL byte.
std::vector<uint8_t> EncodeCollisionMesh(const CollisionMeshMessage& message);

/// Decodes a collision_mesh_t into *out (left as it was on a failure).
/// Rejects malformed bytes (wrong type hash, truncated, trailing bytes,
/// counts that do not fit the bytes or exceed kMaxCollisionMeshElements, a
/// bad string), a non-finite or non-unit pose (kBadPose), an unknown kind,
/// a watertight flag other than 0/1, a non-finite or negative deviation,
/// a non-finite vertex or a triangle index outside the vertices
/// (kBadValue), and a utime outside [0, kMaxUtime] (kBadTimestamp).
/// @param error  if not null, set to a one-line reason on failure.
bool DecodeCollisionMesh(const void* data, size_t size, CollisionMeshMessage* out, std::string* error,
                         MessageError* reason = nullptr);

}  // namespace graspfill::io
