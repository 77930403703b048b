// SPDX-License-Identifier: BSD-3-Clause
// Measurements of triangle meshes (area, signed volume, closed and
// oriented, winding number, point-triangle distance) and an area-weighted
// surface sampler: the mesh deviation, the planner mesh, the synthetic
// ground truth and the tests use them.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::mesh {

/// Points sampled on a surface, with the unit normals of their triangles.
struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
};

/// `count` points drawn uniformly by area over the mesh, seeded (Rng of
/// core/random.hpp: the same mesh, count and seed give the same points).
/// Points and normals are in the mesh's frame [m]; none for zero area.
SurfaceSamples SampleSurface(const TriangleMesh& mesh, int count, uint64_t seed);

/// Total triangle area [m^2].
double SurfaceArea(const TriangleMesh& mesh);

/// Signed enclosed volume [m^3] (divergence theorem): positive for a closed
/// mesh whose triangles face outwards.
double SignedVolume(const TriangleMesh& mesh);

/// True if every directed edge occurs exactly once and its reverse exactly
/// once: the mesh is closed (each edge shared by two triangles) and
/// consistently oriented.
bool IsClosedOriented(const TriangleMesh& mesh);

/// Axis-aligned bounds of the vertices (empty box for an empty mesh).
Eigen::AlignedBox3d Bounds(const TriangleMesh& mesh);

/// The generalized winding number of `mesh` at `p` (the triangles' solid
/// angles over 4 pi): about 1 inside a closed outward mesh, 0 outside,
/// whatever a ray would graze.
double WindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& p);

/// Distance from `p` to the closest point of triangle (a, b, c).
double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c);

}  // namespace graspfill::mesh
