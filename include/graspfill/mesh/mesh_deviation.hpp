// SPDX-License-Identifier: BSD-3-Clause
// How far a mesh made from a cloud (BuildCollisionMesh) lies from it, both
// ways: the mesh's surface to the cloud (does the mesh bulge where the cloud
// has nothing?) and the cloud to the mesh's surface (does the mesh cover
// every point?).
#pragma once

#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// Distances between a mesh and a cloud [m]; percentiles interpolate
/// linearly (core/percentile.hpp).
struct MeshDeviation {
  /// Points sampled uniformly by area on the mesh, to their nearest cloud
  /// point. A mesh exactly on a cloud of spacing s still reads up to about
  /// s / sqrt(2) here.
  double surface_to_cloud_p50_m{0.0};
  double surface_to_cloud_p95_m{0.0};
  double surface_to_cloud_max_m{0.0};
  /// Every cloud point to the closest point of the mesh's surface.
  double cloud_to_surface_p50_m{0.0};
  double cloud_to_surface_p95_m{0.0};
  double cloud_to_surface_max_m{0.0};
  int surface_samples{0};  ///< points sampled on the mesh [count]
};

/// Measures `mesh` against `cloud` (same frame). Deterministic: the samples
/// come from a fixed seed.
/// @param surface_samples points drawn on the mesh (at least 1).
/// @throws std::invalid_argument if the mesh has no triangles or zero area,
///   the cloud no points, or surface_samples < 1.
MeshDeviation MeasureDeviation(const TriangleMesh& mesh, const ObjectCloud& cloud,
                               int surface_samples = 100000);

/// How far each of `points` lies outside the closed mesh `closed_mesh` [m]:
/// 0 for a point inside, else its distance to the surface. Inside means an
/// odd number of the mesh's triangles crossed by at least two of three rays
/// from the point in fixed, skewed directions (one ray can graze an edge).
/// Single-threaded and deterministic.
/// @param closest_triangle  if not null, gets each point's closest
///   triangle (an index into closed_mesh.triangles), inside or not.
/// @throws std::invalid_argument if the mesh has no triangles.
std::vector<double> OutsideDistances(const TriangleMesh& closed_mesh,
                                     const std::vector<Eigen::Vector3f>& points,
                                     std::vector<int>* closest_triangle = nullptr);

/// OutsideDistances summed up: the stated deviation of a mesh that should
/// hold a cloud.
struct OutsideDeviation {
  double max_m{0.0};          ///< the farthest point outside [m] (0: all inside)
  double p99_m{0.0};          ///< 99th percentile over every point, inside ones as 0 [m]
  int64_t points_outside{0};  ///< points with a distance > 0 [count]
};
OutsideDeviation SummarizeOutside(const std::vector<double>& outside_m);

}  // namespace graspfill::mesh
