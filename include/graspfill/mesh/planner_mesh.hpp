// SPDX-License-Identifier: BSD-3-Clause
// The collision mesh a motion planner can check against (FCL, MoveIt):
// at most max_triangles triangles, watertight, and holding the cloud.
//
// 1. The dense mesh (BuildCollisionMesh, ~80k triangles for a small can)
//    with hold_points: its field lowered around each point the surface
//    would leave outside, so every cloud point is inside and the mesh is
//    still watertight by construction.
// 2. DecimateOutward down to the cap: edge collapses that keep it closed
//    and manifold, never fold a triangle or let it cross another, and only
//    ever move the surface outwards, so it still holds the dense mesh and
//    with it the cloud.
// 3. Where the collapses stop short of the cap (each one left would fold
//    or cross), the dense mesh is built again on cells coarser by the
//    shortfall and decimated again; where even the coarsest cells do not
//    fit, the convex hull is the answer (method and fallback_reason say).
//
// The convex hull asked for: the cloud's (qhull, through Open3D), or, with
// more triangles than the cap, the hull of the decimated mesh's vertices.
//
// Nothing is assumed: the result's watertightness is Open3D's IsWatertight
// and its deviation is measured, the farthest cloud point outside it
// (OutsideDistances; 0 but for points the dense mesh drops as stray skins,
// and float rounding) and how far it stands off the cloud.
#pragma once

#include <cstdint>
#include <string>

#include "graspfill/mesh/collision_mesh.hpp"
#include "graspfill/mesh/mesh_deviation.hpp"
#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// How it was made.
enum class PlannerMeshMethod : int8_t {
  kDense = 0,       ///< the dense mesh fit the cap as it was
  kDecimated = 1,   ///< DecimateOutward
  kConvexHull = 2,  ///< qhull
};
/// "dense", "decimated", "convex_hull".
const char* PlannerMeshMethodName(PlannerMeshMethod method);

/// The range of PlannerMeshConfig::max_triangles [count]: 12 is a box.
constexpr int kMinPlannerTriangles = 12;
constexpr int kMaxPlannerTriangles = 10000000;

/// Parameters of BuildPlannerMesh.
struct PlannerMeshConfig {
  /// The mesh has at most this many triangles [count] (FCL and MoveIt
  /// check a few thousand quickly; the dense mesh of a small can has 84k).
  int max_triangles{5000};
  /// The convex hull instead of the decimated shape.
  bool convex_hull{false};
  /// The dense mesh's parameters (hold_points is always on here).
  CollisionMeshConfig dense;

  /// @throws std::invalid_argument naming the field if out of range
  ///   (max_triangles kMinPlannerTriangles..kMaxPlannerTriangles, dense as
  ///   CollisionMeshConfig::Validate).
  void Validate() const;
};

struct PlannerMesh {
  TriangleMesh mesh;  ///< outward-facing triangles, in the cloud's frame
  /// kConvexHull: asked for, or the last fallback.
  CollisionMeshKind kind{CollisionMeshKind::kDecimated};
  PlannerMeshMethod method{PlannerMeshMethod::kDense};
  /// Open3D's IsWatertight on the result.
  bool watertight{false};
  /// The cloud points outside the mesh (OutsideDistances): max_m is the
  /// stated deviation.
  OutsideDeviation outside;
  /// The dense mesh's cells [m] (coarser than config.dense.cell_m where
  /// the first decimation stopped short of the cap).
  double cell_m{0.0};
  /// The dense mesh's triangles, before any decimation [count].
  int64_t dense_triangles{0};
  /// Why a step fell back ("" when none did): e.g. "decimation stopped at
  /// 6210 triangles on 2 mm cells".
  std::string fallback_reason;
};

/// The planner's mesh of `cloud` (points in G; see the file comment).
/// Deterministic.
/// @throws std::invalid_argument as BuildCollisionMesh, or on an invalid
///   config; std::runtime_error if even the convex hull cannot be made
///   within the cap (a cloud with all points on a plane).
PlannerMesh BuildPlannerMesh(const ObjectCloud& cloud, const PlannerMeshConfig& config);

/// Open3D's IsWatertight of `mesh`.
bool IsWatertight(const TriangleMesh& mesh);

}  // namespace graspfill::mesh
