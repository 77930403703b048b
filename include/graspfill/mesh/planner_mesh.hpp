// SPDX-License-Identifier: BSD-3-Clause
// The collision mesh a motion planner can check against (FCL, MoveIt):
// at most max_triangles triangles, watertight, and holding the cloud.
//
// The dense mesh (BuildCollisionMesh: ~80k triangles for a small can) is
// cut down by Open3D's quadric decimation (Garland-Heckbert), then
// inflated: each vertex moves out along its normal by the farthest
// distance outside the mesh of the cloud points closest to the triangles
// around it, until every point is inside or at most outside_tolerance_m
// outside (measured each round: OutsideDistances). Watertightness is
// Open3D's IsWatertight (edge- and vertex-manifold, no boundary, no
// self-intersection), checked after each step. Where decimation breaks it
// (a non-manifold edge, a self-intersection now and then), its result is
// decimated a little further (to 85%, up to three times); where that or the
// inflation fails (moved vertices can fold triangles over at concave
// spots), the dense mesh is built again on coarser cells until it fits the
// cap, and inflated the same way, or where that folds, moved out through
// its distance field's level set instead (CollisionMeshConfig::offset_m:
// watertight by construction, but by the farthest point everywhere) until
// it holds the cloud; where that fails too, the convex hull is the answer
// (method says which). The convex hull asked for: the cloud's (qhull, through Open3D),
// or, with more triangles than the cap, the hull of the decimated mesh's
// vertices (a closed mesh of V vertices has 2V - 4 triangles, so its hull
// has no more).
//
// The stated deviation is measured, never assumed: the farthest cloud
// point outside the final mesh.
#pragma once

#include <cstdint>
#include <string>

#include "graspfill/mesh/collision_mesh.hpp"
#include "graspfill/mesh/mesh_deviation.hpp"
#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// How it was made.
enum class PlannerMeshMethod : int8_t {
  kDense = 0,         ///< the dense mesh fit the cap as it was
  kQuadric = 1,       ///< Open3D's quadric decimation
  kCoarseGrid = 2,    ///< the dense mesh rebuilt on coarser cells
  kConvexHull = 3,    ///< qhull
};
/// "dense", "quadric", "coarse_grid", "convex_hull".
const char* PlannerMeshMethodName(PlannerMeshMethod method);

/// The range of PlannerMeshConfig::max_triangles [count]: a tetrahedron's
/// 4 triangles need a cloud of 4 points on a simplex; 12 is a box.
constexpr int kMinPlannerTriangles = 12;
constexpr int kMaxPlannerTriangles = 10000000;

/// Parameters of BuildPlannerMesh.
struct PlannerMeshConfig {
  /// The mesh has at most this many triangles [count] (FCL and MoveIt
  /// check a few thousand quickly; 84k took the dense mesh).
  int max_triangles{5000};
  /// The convex hull instead of the decimated shape.
  bool convex_hull{false};
  /// Cloud points may lie at most this far outside the mesh [m]; the
  /// inflation stops there.
  double outside_tolerance_m{0.0005};
  /// Inflation rounds before giving up on the tolerance [count].
  int max_inflation_rounds{8};
  /// The dense mesh's parameters.
  CollisionMeshConfig dense;

  /// @throws std::invalid_argument naming the field if out of range
  ///   (max_triangles kMinPlannerTriangles..kMaxPlannerTriangles, outside_tolerance_m 0..0.01 m,
  ///   max_inflation_rounds 1..50, dense as CollisionMeshConfig::Validate).
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
  /// The most any vertex moved out [m] (0: no inflation needed).
  double inflation_max_m{0.0};
  int inflation_rounds{0};
  /// The dense mesh's triangles, before any decimation [count].
  int64_t dense_triangles{0};
  /// Why a step fell back ("" when none did): e.g. "quadric: not
  /// watertight after inflation".
  std::string fallback_reason;
};

/// The planner's mesh of `cloud` (points in G; see the file comment).
/// Deterministic.
/// @throws std::invalid_argument as BuildCollisionMesh, or on an invalid
///   config; std::runtime_error if even the convex hull cannot be made
///   within the cap (a cloud with all points on a plane).
PlannerMesh BuildPlannerMesh(const ObjectCloud& cloud, const PlannerMeshConfig& config);

/// Moves vertices out along their normals (Open3D's area-weighted vertex
/// normals) until every point of `points` is inside `mesh` or at most
/// `tolerance_m` outside, in at most `max_rounds` rounds: each vertex by the
/// largest outside distance of the points whose closest triangle has it.
/// @return the rounds run; *moved_max_m: the most a vertex moved in all.
int InflateToContain(const std::vector<Eigen::Vector3f>& points, double tolerance_m,
                     int max_rounds, TriangleMesh* mesh, double* moved_max_m);

/// Open3D's IsWatertight of `mesh`.
bool IsWatertight(const TriangleMesh& mesh);

}  // namespace graspfill::mesh
