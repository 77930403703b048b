// SPDX-License-Identifier: BSD-3-Clause
// Shared pieces of the claw-hole fill (step 7): the hole's frame and fill
// region, the cloud's spacing around a hole, PCA planes and normals, and
// the seed of each hole's samples. Internal to the repair library.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <vector>

#include "graspfill/core/random.hpp"
#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair::fill {

using Box = Eigen::AlignedBox3f;

/// Throws std::invalid_argument (prefixed by `what`) on a non-finite
/// coordinate.
void CheckFinite(const PointList& points, const char* what);
/// The inputs of a fill: finite points, as many finite normals (if given),
/// an index over the very same cloud (if given); throws otherwise.
void CheckInputs(const PointList& points, const std::vector<Eigen::Vector3f>* normals,
                 const NeighborIndex* index, const char* what);

/// The seed of a fill's sample stream `stream` (one per hole), for
/// graspfill::Rng (core/random.hpp).
uint64_t MixSeed(uint64_t seed, uint64_t stream);

// Sampling of the cloud around some of its points: D (mean distance to the
// nearest neighbour) and the surface density. The density comes from the
// k-th neighbour radius (pi r_k^2 rho ~ Gamma(k, 1) on a surface sampled at
// rho), so it holds for random and for grid-like (TSDF) samplings alike,
// where D alone would be off by a factor that depends on the pattern.
struct Spacing {
  double mean_nn_m{0.0};
  double density_per_m2{0.0};
};

Spacing EstimateSpacing(const NeighborIndex& index, const std::vector<int>& subset, size_t max_queries);

// PCA normals of `subset` (distinct indices; knn over the whole cloud),
// oriented away from `centre`: right for the convex-ish objects a claw
// holds, and cheap, where Open3D's consistent tangent-plane orientation
// takes seconds.
std::vector<Eigen::Vector3f> EstimateNormals(const NeighborIndex& index, const std::vector<int>& subset,
                                             int k, const Eigen::Vector3f& centre);

/// Median of `values` (the upper one of an even count); 0 when empty.
double Median(std::vector<double> values);

// At most `max_count` of `indices`, evenly strided: the fits need ~2000
// points, and their cost then stays flat on dense clouds.
std::vector<int> Thin(const std::vector<int>& indices, size_t max_count);

/// Mean of the points.
Eigen::Vector3f Centroid(const PointList& points);

// Origin and normal from the plane of the hole's rim (PCA), n outward, v
// along V's z projected on that plane (the holes stand upright in V), u
// across. The rim, not the support, sets the plane: a hole at a cuboid's
// corner has a support that wraps over the edge, while its rim stays on
// its own face.
struct HoleFrame {
  Eigen::Vector3d origin{Eigen::Vector3d::Zero()};
  Eigen::Vector3d e1{Eigen::Vector3d::UnitX()}, e2{Eigen::Vector3d::UnitY()}, n{Eigen::Vector3d::UnitZ()};

  Eigen::Vector3d Local(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - origin;
    return {d.dot(e1), d.dot(e2), d.dot(n)};
  }
  Eigen::Vector3d World(double u, double v, double w) const { return origin + u * e1 + v * e2 + w * n; }
};

HoleFrame MakeHoleFrame(const PointList& rim, const PointList& points, const std::vector<int>& support,
                        const Eigen::Vector3d& outward_hint);

// The plane of `pts` as a hole frame: n away from `centroid`, v along
// z projected on the plane.
HoleFrame FrameFromPlane(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3f& centroid);

// Where a hole's fill may go, in its frame: the rim's (u, v) rectangle
// padded, and a range of heights along n. The paper takes the rim's
// bounding box in V; on a doubly curved surface (sphere, ellipsoid) the
// surface over the hole bulges out of that box (by ~2.5 mm for the
// protocol's holes on the 8 cm sphere), so the rectangle is taken in the
// hole's frame and the height is left free or bounded generously.
struct FillRegion {
  Eigen::Vector3d lo, hi;
  // V's z range of the rim (padded): a side hole's fill must not grow into
  // the missing top (V's +z) however the surface bends.
  double z_lo{-std::numeric_limits<double>::infinity()};
  double z_hi{std::numeric_limits<double>::infinity()};
  bool Contains(const Eigen::Vector3d& local) const {
    return (local.array() >= lo.array()).all() && (local.array() <= hi.array()).all();
  }
  bool InZ(double z) const { return z >= z_lo && z <= z_hi; }
};

// The rim's box in f's local coordinates, padded by `pad` in u and v, with
// V's z range [z_lo, z_hi].
FillRegion RimRegion(const PointList& rim, const HoleFrame& f, double pad, double z_lo, double z_hi);

}  // namespace graspfill::repair::fill
