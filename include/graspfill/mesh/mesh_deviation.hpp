// SPDX-License-Identifier: BSD-3-Clause
// How far a mesh made from a cloud (BuildCollisionMesh) lies from it, both
// ways: the mesh's surface to the cloud (does the mesh bulge where the cloud
// has nothing?) and the cloud to the mesh's surface (does the mesh cover
// every point?).
#pragma once

#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// Distances between a mesh and a cloud [m]; percentiles interpolate
/// linearly (eval::Percentile).
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

}  // namespace graspfill::mesh
