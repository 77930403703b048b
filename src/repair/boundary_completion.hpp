// SPDX-License-Identifier: BSD-3-Clause
// Step 6 of the hole repair (Cui et al. 2021, section 2.2.4): closing the
// boundaries that classification left open, with a cubic B-spline fitted
// to the missing surface's boundary.
//
// The curve: a closed (periodic) uniform cubic B-spline, fitted by least
// squares to the missing-surface boundary points in V, parameterised by
// their angle theta around V's z-axis and written in polar form, radius
// r(theta) around that axis. The angle, not the chord length, is the
// parameter because the points have gaps where the claw holes were, and a
// chord-length parameter would shrink each gap to the length of its chord.
// The polar form bridges a gap in a circle exactly (r is constant) and an
// ellipse's within a fraction of a millimetre. The least squares carry a
// small penalty on the control points' third differences, so that control
// points no data reaches (inside a gap) continue the curve smoothly
// (locally quadratic) instead of being undetermined. (The paper calls the
// boundary points "control points"; an interpolating spline through a
// boundary band two points wide would wiggle.) The rim must be star-shaped
// around the axis, as the paper's symmetric objects' rims are.
//
// The height z is the rim's least-squares plane over (x, y): step 4 took
// the rim as planar, and a spline in z would carry the slope of the few
// points at a gap's edge (a claw side's top) across the gap. Points well
// below that plane are such side points and leave the fit; where the
// band's radius depends on its height (a sphere's wall flares out below
// the cut) the radii are first projected to the plane's height.
//
// Inside each gap the samples are clamped between the chord of the gap's
// ends and the tangent lines of the boundary at them: the rim of a convex
// section lies there, and the spline, which cannot turn a sharp corner,
// would otherwise bulge out where a gap ends at one (the cuboid's claw
// holes end 0.4 mm before its corners).
//
// The curve is resampled uniformly in arc length at the boundary's own
// point spacing. Those samples:
//  - fill the missing surface's boundary where a gap is wider than
//    `gap_factor` spacings (the claw holes' mouths), after which it is
//    ordered by angle and closed;
//  - close each open claw boundary across its mouth: from its last point
//    along the rim to its first (the arc that holds the claw's own mean
//    angle), with straight connectors if its ends are off the curve.
// Without a usable curve (no missing surface, too few points, less than
// `min_coverage_rad` of the rim seen) boundaries are closed by straight
// segments. Closed claw boundaries (middle grasps) are left as they are.
//
// Pure and single-threaded.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Parameters of the rim curve and of CompleteBoundaries. Lengths in
/// meters, in V.
struct CompletionConfig {
  /// Spacing of the added points; 0: the median distance between
  /// consecutive points of the missing-surface boundary (else of all
  /// boundaries), at least `min_spacing_m`.
  double spacing_m{0.0};
  double min_spacing_m{0.0003};
  /// Control points: one per this many data points, within [min, max]
  /// (64 over 360 degrees: a knot every 5.6 degrees, a 90 degree box
  /// corner rounded over ~5 mm).
  double points_per_control_point{6.0};
  int min_control_points{12};
  int max_control_points{64};
  /// Weight of the third-difference penalty, relative to the data (per
  /// data point per control point). Small: it only decides where no data
  /// reaches.
  double smoothing{1e-2};
  /// A gap between consecutive missing-surface points longer than this
  /// many spacings (along the curve) is filled.
  double gap_factor{2.5};
  /// Points more than max(this, 2.5 robust sigma) below the rim's plane
  /// are the top of a claw hole's side, not rim, and are left out of the
  /// fit (with a boundary band 2 mm deep, a sphere's side points there lie
  /// 3 mm out from the rim).
  double max_below_rim_m{0.0015};
  /// The curve needs this many points covering this much angle.
  int min_fit_points{10};
  double min_coverage_rad{1.5707963267948966};  ///< 90 degrees
  /// A claw boundary's end farther than this from the curve is not on the
  /// rim: the claw is closed by a straight segment instead.
  double max_rim_distance_m{0.01};

  /// Throws std::invalid_argument naming the first invalid field.
  void Validate() const;
};

/// A closed curve around an axis parallel to V's z: the periodic cubic
/// B-spline r(theta) and the plane z(x, y) of the file comment.
class RimCurve {
 public:
  /// Fits the curve to `points_V` (non-finite points ignored). The axis is
  /// V's z-axis (x = y = 0, the cloud's axis; see EstimateVirtualFrame),
  /// or, if the points do not surround it, the centre of the circle fitted
  /// to them. nullopt, with the
  /// reason in `why`, when there are fewer than min_fit_points points, they
  /// cover less than min_coverage_rad, or the fit is degenerate.
  static std::optional<RimCurve> Fit(const PointList& points_V, const CompletionConfig& config,
                                     std::string* why = nullptr);

  /// The curve's point at angle `theta` [rad] around the axis.
  Eigen::Vector3f At(double theta) const;
  /// Angle of p_V around the axis, in (-pi, pi].
  double AngleOf(const Eigen::Vector3f& p_V) const;
  /// Points spaced uniformly in arc length by about `spacing_m` (exactly
  /// length / round(length / spacing_m)) around the whole curve, with their
  /// angles (increasing from -pi) in `angles` if given.
  PointList Resample(double spacing_m, std::vector<double>* angles = nullptr) const;

  const Eigen::Vector2d& axis_xy() const { return axis_xy_; }

 private:
  RimCurve() = default;
  double Radius(double theta) const;

 public:
  /// Height of the rim's plane at (x, y) in V [m].
  double HeightAt(double x, double y) const;

 private:
  Eigen::Vector2d axis_xy_{0, 0};
  Eigen::VectorXd r_;  ///< control values of r(theta) [m]
  /// z = c0 + c1 x + c2 y: the rim's least-squares plane [m].
  Eigen::Vector3d height_plane_{0, 0, 0};
};

/// Closes every boundary of `boundaries` (from ClassifyBoundaries, in V)
/// as the file comment says; closed = true afterwards for all of them and
/// the added points have source_index -1. Throws std::invalid_argument on
/// an invalid config, a null pointer or a boundary whose source_indices
/// and points_V differ in size. ~0.3-0.5 ms for a 400-point rim.
void CompleteBoundaries(std::vector<HoleBoundary>* boundaries, const CompletionConfig& config);

}  // namespace graspfill::repair
