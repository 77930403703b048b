// SPDX-License-Identifier: BSD-3-Clause
// graspfill's refinement of the virtual frame's axis (not in the paper).
//
// Step 4 takes V's z from a plane fitted to the rim of the missing
// surface. On a fused cloud that rim is ragged (the claw's cut, the TSDF's
// rounded edge) and the plane tilts by 3-6 degrees; the mirrored top then
// leans and the outline checks of step 8 reject the symmetry (measured on
// the replayed clouds of an elliptic cylinder, a cuboid and a sphere:
// 2.8, 6.3, 2.8 degrees off the true axis).
//
// The side walls know the axis better: on a prism-like object (cuboid,
// prisms, cylinders) every side normal is orthogonal to the axis, and on a
// body of revolution (sphere, ellipsoid) the normals of the band around
// the largest section nearly are. So the axis is refined to the direction
// least represented among the side normals: the eigenvector of the
// smallest eigenvalue of sum(n n^T) over the points whose normal is within
// `side_band_rad` of orthogonal to the current axis, a few times over.
// Thousands of side points average the noise out; a sphere's band gives
// back the axis it was given (no information, no harm). The refined axis
// may move 10 degrees from the initial one (the rim plane's, or the up
// hint's), or 40 when the side walls are straight enough to fix it (a
// tilted grasp).
//
// Pure and single-threaded.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

struct AxisRefineConfig {
  /// false: keep step 4's axis (the paper).
  bool enabled{true};
  /// Side points: normals within this of orthogonal to the axis [rad]
  /// (20 degrees).
  double side_band_rad{0.3490658503988659};
  /// Fewer side points than this fraction of the cloud: no refinement.
  double min_side_fraction{0.2};
  /// The refined axis may move at most this far from the initial one
  /// [rad] (10 degrees): beyond it step 4's plane is the better guess.
  double max_change_rad{0.17453292519943295};
  /// ... unless the side walls fix the axis: the smallest eigenvalue of
  /// their normals' scatter is at most this share of its trace (straight
  /// walls: 0.002-0.006 on the zoo's cans, boxes, prisms and bottles; round
  /// bodies, whose band says little: 0.037-0.041) ...
  double straight_wall_share{0.015};
  /// ... then it may move up to this: an object hanging tilted in an
  /// oblique grasp, 20 degrees off the claw's axis (the hint), or under a
  /// rim plane that leans the other way (a cuboid's: 31.5 degrees off);
  /// under 45 degrees, so never onto a box's other pair of faces [rad] (40
  /// degrees).
  double straight_max_change_rad{0.6981317007977318};
  int iterations{4};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

struct AxisRefinement {
  Eigen::Vector3d axis{0, 0, 1};  ///< unit, same side as the initial one
  bool refined{false};            ///< false: the initial axis, unchanged
  double change_rad{0.0};         ///< angle between initial and refined
  /// The side normals' smallest scatter eigenvalue over its trace (0 for
  /// walls exactly parallel to the axis).
  double smallest_share{0.0};
  std::string note;  ///< why not, when !refined
};

/// Refines `initial_axis` (unit, input frame) from the cloud's unoriented
/// unit `normals` (one per point; zero vectors are ignored).
/// @throws std::invalid_argument on a bad config, mismatched sizes or a
///         non-unit initial axis.
AxisRefinement RefineAxis(const std::vector<Eigen::Vector3f>& normals, const Eigen::Vector3d& initial_axis,
                          const AxisRefineConfig& config);

/// `frame` turned so that its z is `axis` (unit, input frame): x is the old
/// x made orthogonal to it, the origin moves along z to the cloud's lowest
/// point, and the box is recomputed over `cloud` (input frame).
VirtualFrame WithAxis(const VirtualFrame& frame, const Eigen::Vector3d& axis, const PointList& cloud);

}  // namespace graspfill::repair
