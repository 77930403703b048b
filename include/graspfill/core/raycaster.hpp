// SPDX-License-Identifier: BSD-3-Clause
// A small RAII wrapper over an Embree 3 triangle scene, shared by the claw
// mask and the synthetic renderer. Build the scene once (AddMesh, Commit),
// then cast as many rays as needed; casting never allocates.
//
// Thread safety: Cast* are const and may run concurrently after Commit();
// AddMesh/Commit/Clear must not overlap with casting (Embree's own rule).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>

#include "graspfill/types.hpp"

namespace graspfill {

/// Result of one ray: distance along the (unit) direction, or +inf on a miss.
struct RayHit {
  float t{std::numeric_limits<float>::infinity()};
  unsigned geom_id{~0u};            ///< id returned by AddMesh
  Eigen::Vector3f normal{0, 0, 0};  ///< unnormalized geometric normal
  bool hit() const { return t < std::numeric_limits<float>::infinity(); }
};

class Raycaster {
 public:
  /// Creates the Embree device; throws std::runtime_error if Embree fails.
  Raycaster();
  ~Raycaster();
  Raycaster(const Raycaster&) = delete;
  Raycaster& operator=(const Raycaster&) = delete;

  /// Adds a mesh (in the scene's frame) and returns its geometry id.
  /// Throws if the mesh has an index out of range.
  unsigned AddMesh(const TriangleMesh& mesh);
  /// Builds the BVH. Must be called after the last AddMesh, before casting.
  void Commit();
  /// Removes every mesh (the next Commit builds an empty scene).
  void Clear();
  bool committed() const;

  /// First hit of the ray origin + t * dir, t in [t_near, t_far].
  RayHit Cast(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near = 0.0f,
              float t_far = std::numeric_limits<float>::infinity()) const;

  /// Any hit of the ray within [t_near, t_far]: cheaper than Cast.
  bool Occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_near, float t_far) const;

  /// Packet of up to 16 rays sharing an origin; directions are [16][3]
  /// (x,y,z per ray), `count` <= 16. Writes the hit distances (+inf on miss).
  void Cast16(const Eigen::Vector3f& origin, const float (*dirs)[3], int count, float* t_out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill
