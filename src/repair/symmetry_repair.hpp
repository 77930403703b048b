// SPDX-License-Identifier: BSD-3-Clause
// Step 8 of the hole repair (Cui, Zhang & Wang, Sensors 2021, section
// 2.3.2): the missing top is filled by mirroring the bottom of the object
// about a horizontal symmetry plane z = z_s of the virtual frame V, the
// cross-section of largest area.
//
// Cross-section size: the cloud is cut into horizontal slabs (thickness a
// few D, the mean nearest-neighbour distance) between its lowest point and
// the missing surface's boundary. Each slab's outline is the 2D convex hull
// of its points on xOy (a hull bridges the claw holes, which an occupancy
// count would not), described by its support function h(theta) (distance
// of the hull's tangent line in direction theta) at 72 directions. The
// size is the squared median over the directions of h / h_ref, h_ref the
// outline at the median height: the squared scale for sections of one
// shape (sphere, ellipsoid, cone), 1 for a prism. A claw hole dents h only
// over the directions it faces, and up to half of them leave the median
// unchanged, where the hull's area loses a few percent (that moved the
// plane of the protocol's ellipsoid by 1.3 mm). Best of all, pass step 7's
// claw-hole fills along (`added_before_V`).
//
// Symmetry plane: when at least `prism_fraction` of the slabs are within
// `plateau_tolerance` of the median slab's size (a prism-like shape, even
// with a few odd slabs by the claw holes; sizes of the observed points
// alone), the middle of the observed height. Otherwise the slabs within
// `plateau_tolerance` of the largest size form runs; the run nearest the median z (the paper starts there) is
// the largest cross-section. z_s is then refined, within the run, to the height about which the size profile
// is most symmetric (least squared difference of the sizes at z_s + t and z_s - t): on a sphere or an
// ellipsoid that is the equator, pinned down by the steep flanks of the
// profile rather than by where its flat top crosses a threshold. On a
// prism-like shape (cuboid, cylinder, prism) every slab has the same size:
// the run spans the whole observed height and z_s is its middle, so the
// mirrored bottom closes the object at the boundary. The height of a band
// cut off the top of such a shape cannot be observed; this "minimal
// closure" is the only choice the data support.
//
// The missing surface's box: x, y from the boundary's extent (with a
// constant section also the rim's whole outline: the boundary test may find
// only part of the rim), z from the boundary up to 2 z_s - min z (padded by
// 2 D). Every point whose mirror image z' = 2 z_s - z lands in the box is
// added unless an original point lies within D of it (the original is
// kept).
//
// Plausibility (graspfill's addition, never a mirrored wrong shape): the
// object is declared not symmetric, and nothing is added, when
//  - the part above z_s is longer than the part below (the mirror of the
//    observed top would fall below the object: e.g. a cone or a frustum),
//  - the mirror would add more than `max_added_height_fraction` of the
//    observed height above the boundary (the largest section is low: e.g. a
//    bump or a step near the bottom),
//  - or more than `outlier_checks` of the slabs above z_s and their mirror
//    images below have outlines that differ by more than
//    `max_outline_mismatch` (median over the directions
//    of the difference of their support functions about their common
//    centre, relative to the mean support: robust to the claw holes' dents;
//    a lateral shift counts).
//
// Frames and units: points in V [m] (+z towards the missing surface).
// Threads: single-threaded, deterministic, no state.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// Settings of the symmetry fill. D is the cloud's mean nearest-neighbour
/// distance (estimated on a subset of the points).
struct SymmetryConfig {
  /// Slab thickness of the cross-section profile, in D; at least
  /// `min_slab_thickness_m`. 4 D keeps ~4 rows of points of a random
  /// sampling in a slab, enough for a hull that reaches the outline.
  double slab_thickness_d{4.0};
  double min_slab_thickness_m{0.0005};
  /// Slabs with fewer points than this get no size (ignored).
  int min_slab_points{8};
  /// Slabs with a size of at least (1 - this) x the largest belong to the
  /// largest cross-section (sampling noise, residual dents).
  double plateau_tolerance{0.05};
  /// Prism-like when at least this fraction of the slabs are within
  /// plateau_tolerance of the median slab's size: plane at mid-height.
  /// (A cuboid with a 3 cm bump on 13 cm: 77%; fused clouds of prisms and
  /// cylinders: 95% and more.)
  double prism_fraction{0.85};
  /// A run of the largest cross-section that reaches within this many
  /// slabs of the lowest and of the highest slab spans the whole observed
  /// height (a prism-like shape).
  int end_slack_slabs{2};
  /// false: the paper as written, from the median slab uphill to the
  /// nearest local maximum of the size (on a flat profile it stays at the
  /// median, which the bottom face pulls low: 45.7 mm instead of 70 on the
  /// protocol's cylinder).
  bool plateau_search{true};
  /// Run the plausibility checks (the paper has none).
  bool check_symmetry{true};
  /// Largest outline mismatch allowed between a slab above z_s and its
  /// mirror image (see above; ~0.01 for the protocol's shapes with their
  /// claw holes, ~0.17 for a square against the same square turned by 45
  /// degrees).
  double max_outline_mismatch{0.05};
  /// Slab pairs compared by the outline check (spread over the observed
  /// part above z_s) ...
  int outline_checks{8};
  /// ... of which this many may mismatch (a fused cloud's rounded bottom
  /// edge, a ragged slab by the claw holes: 11-12% on one pair each).
  int outlier_checks{2};
  /// Largest height the mirror may add above the boundary, as a fraction
  /// of the observed height (boundary z - min z): the camera misses a top,
  /// not most of the object.
  double max_added_height_fraction{0.5};
  /// Slack of the "part above shorter than the part below" check, in slab
  /// thicknesses.
  double range_tolerance_slabs{1.5};
  /// Points used to estimate D.
  int spacing_samples{1000};
  /// The image is moved radially onto the observed walls where the two
  /// overlap above the plane (a fruit that leans, a top a little wider
  /// than the base; see FitImageToObserved in the source), on a polar grid
  /// of slabs and this many sectors; 0: the mirror as it is (the paper).
  int fit_sectors{36};
  /// An image point takes the mean offset of the cells within this many
  /// slabs and sectors of its own (a claw hole is up to ~4 sectors wide).
  int fit_reach_cells{2};
  /// Cells whose observed and image walls lie farther apart than this are
  /// another part of the object, not the same wall off by a lean [m].
  double fit_max_offset_m{0.004};

  /// The paper as written: hill climb from the median, no checks.
  static SymmetryConfig Paper();
  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

struct SymmetryResult {
  /// Mirrored points in V [m] (empty unless `symmetric`).
  PointList added_V;
  /// z of the symmetry plane in V [m] (NaN when none could be computed).
  double symmetry_plane_z{std::numeric_limits<double>::quiet_NaN()};
  /// A plausible symmetry plane was found and used.
  bool symmetric{false};
  /// The plane is a prism's mid-height: the walls run straight up to the
  /// rim, so the image closes the top with a lid that no view saw and no
  /// wall implies (a mouth would end them alike).
  bool constant_section{false};
  /// Why not, when !symmetric; a short note otherwise.
  std::string reason;
  /// Largest outline mismatch of the checked slab pairs (0 when none was
  /// checked).
  double outline_mismatch{0.0};
  /// The missing surface's box in V [m] (empty box when none).
  Eigen::Vector3f box_min_V{0, 0, 0};
  Eigen::Vector3f box_max_V{0, 0, 0};
};

/// Fills the missing surface by symmetry (paper 2.3.2).
/// @param points_V the object cloud in V [m], finite coordinates.
/// @param missing_surface the missing surface's boundary (points in V;
///        its kind is not checked).
/// @param index_V optional neighbour index built over points_V (the same
///        vector object); built here when null. Only D is taken from it.
/// @param added_before_V optional points added by earlier steps (step 7's
///        claw-hole fills), used like the cloud's (cross-sections, overlap,
///        mirroring), except in the constant-section test, which asks the
///        observed points alone (fills ~1 mm proud of a box's narrow face
///        widen its sections by 3-9%). Pass them: they take the claw
///        holes' dents out of the cross-sections (the protocol's
///        ellipsoid: plane 0.64 mm low without them, 0.01 mm with).
/// @param open_holes_V optional boxes (V) of holes beside the top that no
///        surface fit explained (RepairClawHoles' left-open ones) or that
///        no boundary line took (clusters of loose boundary points: finger
///        pads that open into the missing top): the mirror image fills
///        them too, where it lands in them beside no original point.
/// @return the mirrored points and the plane; on an empty cloud, a
///         boundary of fewer than 3 points or an implausible symmetry,
///         nothing added and the reason.
/// @throws std::invalid_argument on a bad config, non-finite coordinates or
///         an index over another cloud.
SymmetryResult RepairMissingSurface(const PointList& points_V, const HoleBoundary& missing_surface,
                                    const SymmetryConfig& config, const NeighborIndex* index_V = nullptr,
                                    const PointList* added_before_V = nullptr,
                                    const std::vector<Eigen::AlignedBox3f>* open_holes_V = nullptr);

}  // namespace graspfill::repair
