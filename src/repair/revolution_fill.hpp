// SPDX-License-Identifier: BSD-3-Clause
// A surface of revolution about an axis parallel to V's z, fitted to the
// observed points: x^2 + y^2 = 2 x0 x + 2 y0 y + a + b z + c z^2, linear in
// its five unknowns (the axis (x0, y0) and the radius profile r(z)^2, a
// quadric of revolution: a sphere, a spheroid, a cone, a cylinder). One of
// the missing top's hypotheses (top_search.hpp): when the profile closes
// by itself above the observed top (r^2 reaches 0: a ball, a fruit, a
// cone's tip), its surface over the unseen part is the completion. Thrun
// & Wegbreit 2005 ("Shape from symmetry") count rotational symmetry among
// the symmetries a partial view implies. Internal to graspfill_repair.
//
// Frames and units: points in V [m] (+z towards the missing top).
// Pure, single-threaded, deterministic.
#pragma once

#include <optional>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

struct Revolution {
  double x0{0.0}, y0{0.0};        ///< the axis [m, V]
  double a{0.0}, b{0.0}, c{0.0};  ///< r(z)^2 = a + b z + c z^2 [m^2]
  double pole_z{0.0};             ///< where r^2 reaches 0 above the fit [m]
  double rms_m{0.0};              ///< radial RMS of the inliers [m]

  double RadiusSquared(double z) const { return a + (b + c * z) * z; }
  /// The outward unit normal at `p` (on or near the surface): the gradient
  /// of r^2 - r(z)^2; zero where it vanishes.
  Eigen::Vector3f Normal(const Eigen::Vector3f& p) const;
};

/// Fits the surface to `points_V` (reweighted twice: points farther than
/// 3 x the RMS from it, another part of the object, drop out). nullopt
/// when the fit is degenerate or r^2 does not reach 0 within `reach_m`
/// above `top_z` (a cylinder, a cup's flare: nothing closes them).
std::optional<Revolution> FitRevolution(const PointList& points_V, double top_z, double reach_m);

/// The surface sampled `spacing_m` apart from `from_z` to the pole, where
/// the cloud leaves it open: no point of `taken_V`, moved radially onto
/// the surface, lies within a spacing (so the model's own error off the
/// seen surface, a ball's panels, opens no hole). Each sample's `in_hole`
/// says whether none lies within `hole_m` either (a hole, not the gaps
/// between seen points).
struct RevolutionSamples {
  PointList points_V;
  std::vector<char> in_hole;
};
RevolutionSamples SampleRevolution(const Revolution& surface, double from_z, double spacing_m, double hole_m,
                                   const PointList& taken_V);

}  // namespace graspfill::repair
