// SPDX-License-Identifier: BSD-3-Clause
// Step 7 of the hole repair (Cui, Zhang & Wang, Sensors 2021, section
// 2.3.1): the claw holes on the side of the object are filled from a
// surface fitted to the points around them, sampled inside each hole's
// extent in the virtual frame V. The paper's surface is a screened Poisson
// reconstruction (Open3D's port of Kazhdan & Hoppe 2013) of all the side
// points; graspfill's default fits a small explicit surface per hole
// (ClawSurface::kLocalFit), which is exact on the paper's shapes, keeps
// sharp edges, and costs ~10-30 ms for three holes of a 50k-point cloud
// where a single Poisson solve costs 0.3-1 s (numbers in the .cpp).
//
// (The benchmark's "Poisson-only" baseline, every hole filled from one
// Poisson surface of the whole cloud, is not part of the library:
// src/repair/poisson_baseline.hpp.)
//
// Frames and units: every point is in meters; the claw-hole function works
// in V (see repair_types.hpp).
// Threads: single-threaded (Open3D's Poisson is run with one thread) and
// deterministic: the same input and config give the same points. Open3D's
// Poisson keeps a process-wide thread pool: do not run two of these calls
// concurrently when they use Poisson.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// The surface a claw hole is filled from.
enum class ClawSurface {
  /// Screened Poisson (Open3D), as in the paper.
  kPoisson,
  /// Per hole, the candidate most consistent with the points around the
  /// hole (its "support") and with its rim:
  ///  - a height field w = p(u, v) (polynomial of `polynomial_degree`) over
  ///    the plane of the rim, fitted by iteratively reweighted least squares
  ///    (Tukey biweight), so that points past a sharp edge do not bend it;
  ///  - an implicit quadric (Taubin's fit, reweighted likewise), when its
  ///    residuals are less than half the height field's: spheres, ellipsoids
  ///    and cylinders are quadrics, so a hole of any size on them is filled
  ///    exactly, where the height field sags by ~1 mm over a hole spanning
  ///    ~90 degrees of a sphere (pairs of planes are refused);
  ///  - two height fields, one per face of a convex edge (a hole at a
  ///    cuboid's corner), the faces told apart by the points' normals, each
  ///    used where it lies inside the other.
  /// A candidate must explain 90% of the rim's points; when none does (a
  /// rounded edge, a rim a fused cloud leaves ragged), the hole falls back
  /// to a thin-plate spline over the rim's plane, fitted to the support's
  /// points that face the hole's way (a 256-centre solve, ~5-20 ms a hole;
  /// the local Poisson surface it replaces cost 0.3-0.8 s).
  kLocalFit,
};

/// Settings of the claw-hole fill. D below is the mean nearest-neighbour
/// distance of the cloud around the hole (the paper's D-bar of Eq. 5).
struct ClawRepairConfig {
  /// Which surface fills the holes.
  ClawSurface surface{ClawSurface::kLocalFit};

  // --- Points around a hole (both surfaces) ---
  /// Margin around a hole's box [m]: the cloud points within it are the
  /// hole's "support" (the fit's input, its density and normal). Wide
  /// enough to give the surface support all around the hole, narrow enough
  /// to stay on the face the hole is in.
  double local_margin_m{0.010};
  /// Holes with fewer support points than this are skipped.
  int min_support_points{30};
  /// A "hole" whose support holds more than this share of the cloud is no
  /// finger's: a rim round much of a partly seen object (the open side of
  /// a cloud extracted half way through the turn). It is left open and
  /// counted, as the planner's safe bound holds that space; filling it
  /// took up to 5 s and drew 61k points for a 20k-point cloud (a can at
  /// 150 of 300 frames, `bench live`'s full repairs). 1 = no limit (paper).
  double max_support_share{0.5};
  /// The fill of a hole in a wall (its rim's normal within 45 degrees of
  /// horizontal) or reaching the cloud's upper half: its samples deeper
  /// than this [m] inside the convex outline of the observed points at
  /// their height (a slab 2 D thick) are inside the object and dropped (a
  /// hole that opens into the top, sampled over the top rim's shadow, ran
  /// under the top; a sheet over a rounded box, or under a round top,
  /// bent into it). A horizontal face lower down (a bottom) lies inside
  /// its own outline: not tested. 3 mm: the zoo's "wrong" distance; a
  /// wall leaning up to ~70 degrees keeps its own samples. 0 = no test
  /// (paper).
  double max_inside_outline_m{0.003};
  /// The same fills' samples farther than this [m] past the widest
  /// observed point of their slab, measured from the slab's centre (the
  /// centre of the circle fitted to its points), are outside the object
  /// and dropped; only where the slab is round (the RMS of its points'
  /// distances from the centre under this / 2.8: an ellipse's or a box's
  /// widest points may be the ones the claw hides). A surface fitted over
  /// a hole whose rim climbs a shoulder bulges out over a narrow neck
  /// (3-5 mm outside a bottle's, where V's axis misses the neck's by a few
  /// mm). Unlike the outline's chord across a wide
  /// hole, the widest point bounds a round section wherever the hole is.
  /// 0 = no test (paper).
  double max_outside_widest_m{0.002};
  /// Fills above the missing top's rim (its highest point within 15
  /// degrees around V's axis) and more than this [m] inside its convex
  /// outline are on the top, which the top's repair closes: dropped by
  /// DropFillsOnTheTop. A finger's hole that opens into a round top is
  /// sampled over its rim's box, which reaches over the rim into the cap,
  /// where a surface fitted to the side below sags (3-4 mm inside a
  /// ball's). A wall rising past the rim stays on the
  /// outline. 0 = no test (paper).
  double max_inside_top_rim_m{0.001};

  // --- kLocalFit ---
  /// Degree of the height fields (1 to 5). 4 follows a 7 cm cylinder's side
  /// over a 45 mm wide patch to ~0.05 mm.
  int polynomial_degree{4};
  /// Height fields with a robust residual scale (1.4826 MAD) above this [m]
  /// are not trusted.
  double max_fit_sigma_m{0.001};
  /// Iterations of the reweighted least squares (3 to 100; a height field's
  /// first two fit a plane).
  int irls_iterations{6};
  // --- kPoisson (the paper's: one Poisson surface of all the side points,
  // shared by the holes) ---
  /// Octree depth of the Poisson solve (paper: 6). The grid spans the
  /// input's bounding cube times `poisson_scale`, so the cell edge is
  /// scale * extent / 2^depth: ~8.8 mm for the paper's 14 cm object.
  int poisson_depth{6};
  /// Ratio of the reconstruction cube to the input's bounding cube (PCL's
  /// and Open3D's `scale`; paper: 4.0). The paper's "min samples per octree
  /// node 16" has no Open3D counterpart (Open3D fixes samples_per_node at
  /// 1.5).
  double poisson_scale{4.0};
  /// Neighbours of the PCA normal estimates (Poisson's input when no
  /// normals are given; at most 10 of them for kLocalFit's face split).
  int normal_knn{16};
  /// Surface triangles whose normal is more than this off the hole's
  /// outward normal are not sampled [deg]: it rejects the far side of the
  /// closed Poisson surface and its folds.
  double max_normal_deviation_deg{75.0};
  /// The Poisson surface sags or bulges over a hole by up to about a cell:
  /// along the hole's normal its samples may lie this many cells (plus
  /// the hole box's pad and a quarter of the hole's width, for the curvature)
  /// beyond the rim (the cell is scale x input extent / 2^depth).
  double poisson_box_pad_cells{1.5};

  // --- Sampling ---
  /// Fill density relative to the support's surface density (points per
  /// m^2, from the 8th-neighbour radius); 1 matches the input. The paper's
  /// Eq. 5 draws N = V / D^3 points in the box and keeps those "on the
  /// surface": with a band of +-D/2 that is A / D^2 points on a patch of
  /// area A. Here the surface itself is sampled at the chosen density, so
  /// every point is on it and none is wasted.
  double fill_density_factor{1.0};
  /// Seed of the sample positions.
  uint64_t seed{7};

  /// The paper's settings: one Poisson surface of the side points, and none
  /// of graspfill's rules around it.
  static ClawRepairConfig Paper();
  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// Fills the claw holes (paper 2.3.1). For each hole: a surface through the
/// cloud points within `local_margin_m` of the box of its boundary, sampled
/// over the boundary's extent (the rim's (u, v) rectangle in the frame of
/// the rim's plane, and no higher or lower in V's z than the rim: the top is
/// step 8's) where neither the cloud nor an earlier hole's fill has a
/// point within a spacing D. (The paper samples the rim's box in V; on a
/// sphere the surface over a claw hole bulges ~2.5 mm out of that box.)
/// @param points_V the object cloud in V [m], finite coordinates.
/// @param claw_holes claw-hole boundaries (points in V, closed after the
///        completion); other kinds and boundaries of fewer than 3 points
///        are ignored.
/// @param normals_V optional outward unit normals of points_V (e.g. the
///        TSDF's); only Poisson needs per-point normals. When null they are
///        estimated where needed (PCA of `normal_knn` neighbours, oriented
///        away from the cloud's centroid: right for the convex-ish objects
///        a claw holds).
/// @param index_V optional neighbour index built over points_V (the same
///        vector object); built here when null.
/// @param holes_left_open optional; receives the holes left open (indices
///   into `claw_holes`): support over `max_support_share`, or (kLocalFit)
///   no explicit surface explains them.
/// @return the new points in V, hole after hole (empty if no holes).
/// @throws std::invalid_argument on a bad config, non-finite coordinates,
///         normals of the wrong size or an index over another cloud.
PointList RepairClawHoles(const PointList& points_V, const std::vector<HoleBoundary>& claw_holes,
                          const ClawRepairConfig& config,
                          const std::vector<Eigen::Vector3f>* normals_V = nullptr,
                          const NeighborIndex* index_V = nullptr,
                          std::vector<size_t>* holes_left_open = nullptr);

/// Drops the `fills_V` that lie on the missing top (see
/// ClawRepairConfig::max_inside_top_rim_m), the top's rim given as
/// `rim_V`; returns how many. A no-op for a rim of fewer than 3 points or
/// a depth of 0.
size_t DropFillsOnTheTop(const PointList& rim_V, double max_inside_m, PointList* fills_V);

}  // namespace graspfill::repair
