// SPDX-License-Identifier: BSD-3-Clause
// The shape zoo's meshes and volumes: household-like objects that go
// beyond the paper's symmetric solids (see Shape in shapes.hpp, whose
// MakeShape and AnalyticVolume call these). All are in frame O (meters,
// +z up, z in [0, H], the bounding box centred in x and y), closed,
// consistently outward-oriented and deterministic.
//
// `segments` is the facet count around a full turn (as for the paper's
// shapes); quarter turns get segments / 4 facets. Sizes are W x D x H [m]
// and must be positive (MakeShape checks that before calling these).
#pragma once

#include <Eigen/Core>

#include "graspfill/types.hpp"

namespace graspfill::synth::internal {

/// Edge radius of the rounded box as a fraction of its smallest side.
inline constexpr double kRoundedBoxEdgeFraction = 0.12;

/// A W x D x H box whose twelve edges are quarter cylinders and whose
/// corners are eighth spheres of radius kRoundedBoxEdgeFraction * min(W,
/// D, H): the core box shrunk by that radius, grown by a ball (Minkowski
/// sum), so the flat faces keep the full bounding box.
TriangleMesh MakeRoundedBox(const Eigen::Vector3d& size_m, int segments);
/// Exact (Steiner's formula for a box grown by a ball).
double RoundedBoxVolume(const Eigen::Vector3d& size_m);

/// Bottle proportions: neck diameter of W; heights of the cylindrical body
/// and of the shoulder as fractions of H (the neck takes the rest).
inline constexpr double kBottleNeckFraction = 0.35;
inline constexpr double kBottleBodyFraction = 0.55;
inline constexpr double kBottleShoulderFraction = 0.20;

/// A capped bottle, a body of revolution with flat ends: a cylinder of
/// diameter W, a shoulder whose radius falls from W/2 to the neck's along a
/// half cosine (no kink at either end), a cylindrical neck up to z = H.
/// D != W makes every section an ellipse (as for the cylinder).
TriangleMesh MakeBottle(const Eigen::Vector3d& size_m, int segments);
/// Exact: each part integrates pi r(z)^2 in closed form.
double BottleVolume(const Eigen::Vector3d& size_m);

/// A fruit-like lump: the star-shaped surface r(u) = 1 + lobes(u) over unit
/// directions u, with low-order lobes (three around the axis, a lean, a
/// flattening and a top-bottom difference) of 7.5% at most together, then
/// scaled per axis so that its bounding box is exactly W x D x H. No mirror
/// plane and no axis of symmetry, but close to an ellipsoid.
TriangleMesh MakeBlob(const Eigen::Vector3d& size_m, int segments);
/// Numerical, no closed form: the volume of the exact surface by
/// quadrature over directions (1/3 the integral of r^3), its bounding box
/// found by a zooming grid search; both to about 1e-6 relative.
double BlobVolume(const Eigen::Vector3d& size_m);

/// Mug handle proportions: the tube radius as a fraction of the handle's
/// reach (W - D) and the vertical semi-axis of its path as a fraction of H.
inline constexpr double kMugTubeFraction = 0.2;
inline constexpr double kMugHandleHeightFraction = 0.3;

/// A lidded mug: a solid cylinder of diameter D and height H (closed so the
/// mesh stays closed) on the -x side of the bounding box, and a handle on
/// +x reaching W - D beyond it: a round tube swept along a vertical half
/// ellipse (in the x-z plane, centred at H/2), its flat ends inside the
/// body, just deep enough to hide their rims. The mesh is the union of
/// these two closed components, not a boolean merge: the renderer
/// ray-casts and never sees the hidden ends, but the surface sampler does
/// (0.7% of the area at the default size). The handle breaks the
/// mirror symmetry about x = 0 (it keeps the one about y = 0).
/// @throws std::invalid_argument unless the handle fits: W > D and the
///         tube neither leaves [0, H] nor folds onto itself (roughly
///         0.1 H < W - D < 0.75 H).
TriangleMesh MakeMug(const Eigen::Vector3d& size_m, int segments);
/// Body plus handle tube (Pappus: tube section times the length of its
/// half-ellipse path, the length by the trapezoid rule, converged to
/// machine precision), the hidden ends counted in both, as the divergence
/// theorem over the two components counts them (under 0.1% of the total
/// at the default size). Same exceptions as MakeMug.
double MugVolume(const Eigen::Vector3d& size_m);

/// Bowl wall thickness, limited to a fraction of the smallest semi-axis
/// for small bowls.
inline constexpr double kBowlWallM = 0.004;
inline constexpr double kBowlMaxWallFraction = 0.25;

/// An open bowl made a closed solid: the outer surface is the lower half of
/// an ellipsoid with semi-axes W/2, D/2, H centred at (0, 0, H), the inner
/// one the same with every semi-axis shortened by the wall (so the bottom
/// inside is at z = wall), joined by a flat rim annulus at z = H. At
/// W = D = 2H both halves are concentric hemispheres (an even wall).
TriangleMesh MakeBowl(const Eigen::Vector3d& size_m, int segments);
/// Exact: the difference of the two half ellipsoids.
double BowlVolume(const Eigen::Vector3d& size_m);
/// The bowl's wall thickness at this size [m].
double BowlWall(const Eigen::Vector3d& size_m);

}  // namespace graspfill::synth::internal
