// SPDX-License-Identifier: BSD-3-Clause
// Step 4 of the hole repair (Cui et al. 2021, section 2.2.3 A): the virtual
// camera frame V, in which the missing surface is the top (largest z).
//
// The paper fits planes to the hole-boundary points by RANSAC, one after
// another, and takes as the missing-surface plane the one whose normal is
// the most nearly orthogonal to the others (Eq. 4). Here:
//  - RANSAC is our own, seeded (std::mt19937_64): Open3D 0.16's
//    PointCloud::SegmentPlane draws from a process-wide engine inside an
//    OpenMP loop, so its result depends on the thread schedule and on every
//    other caller of that engine. It has local optimisation (least-squares
//    refits of promising hypotheses) and preemptive scoring.
//  - Eq. 4 uses |n_k . n_i|: normals are unoriented, and the signed sum
//    would favour two claw planes facing each other (negative dot product).
//  - `prefer_open_planes` (default) looks for the missing surface as what
//    it is, a cut: a plane with the cloud on one side whose own cloud
//    points all lie next to boundary points ("open"). Planes sharing
//    boundary points are allowed (a cuboid's top rim also lies on the face
//    planes, which would otherwise explain it away). Each open cut is
//    refitted to the rim it touches; among them the most open is kept,
//    then the one square to the symmetry axis (the normal through the rim's
//    centre passes through the cloud's centroid), then Eq. 4, then the
//    inlier count. Measured on the paper protocol with ideal boundary
//    points (6 shapes, random poses): Eq. 4 alone (prefer_open_planes =
//    false) picks a side plane on 23 of 60 top grasps (cuboid, prism,
//    elliptic cylinder: a claw plane is as orthogonal to the others as the
//    top; sphere: planes through the claw holes' bottom edges are parallel
//    to the top). The default, on 40 poses per shape and grasp: middle
//    grasps 240 of 240 within 0.3 degrees; top grasps 239 of 240 within
//    1.6 degrees; top-oblique grasps 237 of 240; all failures are on the
//    ellipsoid (9-15 degrees off: its small top rim is mostly notched
//    away by the claw holes, and the refit leans on what is left).
//  - Without an up hint (best mode), the chosen plane is checked against
//    where the boundary lies: the holes gather at the missing top and a
//    grasp's claw holes sit about the object's axis, so the direction from
//    the cloud's centroid to the boundary points' follows the axis (a few
//    degrees off on closed objects). A plane more than 30 degrees from it
//    is taken for a claw hole's, and z is that direction: where the holes
//    notch the top's rim away, the rim's plane can lie 30-70 degrees off.
//  - +z points to the missing surface: the side of the cut without cloud;
//    else (paper mode) the end of the cloud where the boundary crowds. An
//    optional up hint overrides the sign and limits the planes to a cone.
//  - x and y: the edges of the minimum-area rectangle around the cloud
//    projected on the plane (rotating calipers over the 2D convex hull, so
//    a cuboid's x and y follow its faces; a PCA would follow the diagonal
//    of a square section). x is the longer edge, signed so that its largest
//    input-frame component is positive; y = z x x.
//  - The origin is the rectangle's centre, at the cloud's lowest z: the
//    cloud spans z in [0, height] and x = y = 0 is its axis for symmetric
//    shapes, like the object frame of synth/shapes.hpp.
//
// Pure and single-threaded; deterministic for given inputs and config.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Parameters of EstimateVirtualFrame. Distances in meters.
struct VirtualFrameConfig {
  /// RANSAC inlier distance to a plane. 2 mm holds a rim of boundary
  /// points two ~1 mm spaced rows wide plus ~1 mm of noise.
  double plane_distance_m{0.002};
  /// At most this many planes are extracted per search (the paper's
  /// examples show the missing surface, three claw holes and a spurious
  /// plane or two); the paper's search, when it runs as the fallback, adds
  /// up to as many again.
  int max_planes{8};
  /// A plane needs at least max(min_plane_inliers, min_plane_fraction *
  /// boundary points) inliers; extraction stops at the first that has not.
  int min_plane_inliers{20};
  double min_plane_fraction{0.04};
  /// RANSAC iterations per plane: adaptive (stops once `ransac_confidence`
  /// of drawing an all-inlier triple is reached), at most this many.
  int max_ransac_iterations{600};
  double ransac_confidence{0.999};
  uint64_t seed{20210101};
  /// Look for the missing surface among open cuts (see the file comment);
  /// false is the paper: sequential RANSAC planes and Eq. 4 alone. With
  /// true, the paper's way is still the fallback when no open cut exists.
  bool prefer_open_planes{true};
  /// A cloud point within plane_distance_m of a plane counts as "rim" when
  /// a boundary point lies within this distance of it.
  double open_support_radius_m{0.003};
  /// A plane is open when at least this fraction of its cloud support is
  /// rim (a missing top: ~1; claw holes on curved surfaces: 0.6-0.9; a side
  /// face or wall section: < 0.45).
  double min_open_fraction{0.75};
  /// Among the open cuts, only those within this of the most open one
  /// stay candidates (the top, cut by a plane: ~1.0; claw holes on curved
  /// surfaces: 0.7-0.9).
  double open_fraction_tie{0.05};
  /// Then only those whose axis offset (see BoundaryPlane) is within this
  /// of the smallest (the top: < 0.1; a sphere's claw holes: ~0.3).
  double axis_offset_tie{0.1};
  /// Eq. 4 sums within this of the smallest one count as a tie, broken by
  /// the inlier count.
  double eq4_tie_tolerance{0.15};
  /// With an up hint, only planes whose normal is within this angle of the
  /// hint are candidates (if there are any) [rad]. Default 30 degrees.
  double hint_max_angle_rad{0.5235987755982988};
  /// Without an up hint, the chosen plane must agree with where the
  /// boundary lies: the direction from the cloud's centroid to its
  /// boundary points' (the holes gather at the missing top, a grasp's claw
  /// holes sit about its axis). Where the chosen plane's normal is more
  /// than this from that direction (as an axis) [rad], and the direction is
  /// clear (the centroids min_boundary_offset of the cloud's bounding-box
  /// diagonal apart), z is that direction. 0: no check. Default 30 degrees.
  double max_boundary_axis_angle_rad{0.5235987755982988};
  double min_boundary_offset{0.15};
  /// Cloud points more than this beyond a plane count as lying beyond it
  /// (at most 0.2% of them may, for a cut); also the band at the cloud's
  /// ends used for the sign of z in paper mode.
  double extreme_band_m{0.004};
  /// Columns of the O(n) filter that keeps the lowest and highest point of
  /// each column before the 2D hull; the hull is then exact to within
  /// extent / hull_columns.
  int hull_columns{256};

  /// Throws std::invalid_argument naming the first invalid field.
  void Validate() const;
};

/// A plane fitted to the boundary points: normal . p = offset.
struct BoundaryPlane {
  Eigen::Vector3d normal{0, 0, 1};  ///< unit, input frame, sign arbitrary
  double offset{0.0};               ///< [m]
  int inliers{0};                   ///< boundary points within the distance
  double eq4_sum{0.0};              ///< sum over the others of |n . n_i|
  double open_fraction{1.0};        ///< cloud support near boundary points
  bool cut{false};                  ///< the cloud lies on one side of it
  /// Distance from the cloud's centroid to the normal through the centre
  /// of the plane's rim, over the rim's RMS radius; -1 if not computed.
  double axis_offset{-1.0};
  bool chosen{false};  ///< the missing-surface plane
};

/// Estimates V for `cloud` (input frame, meters) from its hole-boundary
/// points `boundary_points` (same frame; usually a subset of the cloud).
/// Non-finite points are ignored.
/// @param up_hint optional direction (input frame, any length > 0) roughly
///   towards the missing surface; not needed.
/// @param failure_reason optional; set when nullopt is returned (too few
///   finite points, no plane with enough inliers).
/// @param planes optional; receives every plane extracted, for reports.
/// @return V with T_in_V mapping V to the input frame and the cloud's
///   bounding box in V; nullopt when no plane is found.
/// Throws std::invalid_argument on an invalid config. Takes ~4-7 ms (one
/// core) for 38k cloud points and 1.3k boundary points.
std::optional<VirtualFrame> EstimateVirtualFrame(const PointList& cloud, const PointList& boundary_points,
                                                 const VirtualFrameConfig& config,
                                                 const Eigen::Vector3d* up_hint = nullptr,
                                                 std::string* failure_reason = nullptr,
                                                 std::vector<BoundaryPlane>* planes = nullptr);

/// The points (input frame) expressed in V: T_in_V^-1 * p.
PointList ToVirtualFrame(const PointList& points_in, const VirtualFrame& frame);

}  // namespace graspfill::repair
