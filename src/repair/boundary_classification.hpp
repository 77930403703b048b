// SPDX-License-Identifier: BSD-3-Clause
// Step 5 of the hole repair (Cui et al. 2021, section 2.2.3 B, Fig. 9):
// splitting the linked boundary lines into the boundary of the missing
// surface (the top, at the largest z of the virtual frame V) and one
// boundary per claw hole.
//
// In a top grasp the claw holes reach the cut top, so one line runs along
// the top rim and dips into each claw hole in turn: down one side, along
// the bottom, up the other side. The sides are the z-monotone segments of
// more than 5 points; their ends on the rim are the demarcation points.
// Each line is walked from its highest point (the paper walks from the
// lowest because its missing surface is at the smallest z); a descending
// segment opens a claw hole and the next ascending one closes it.
//
// Beyond the paper:
//  - "Monotone" tolerates reversals below `monotone_tolerance_m` (a
//    linker zig-zags across a boundary band two points wide), and a
//    segment must also drop `min_segment_height_m` at a slope of at least
//    `min_segment_slope` (rise over chord), so that a rim which V tilts by
//    a few degrees is not taken for a claw side.
//  - A side's end takes in the side points a zig-zag interleaves with the
//    rim's first points, up to 8 places on, until 4 rim points come in a
//    row: a dip of the rim beyond them (a fused box's corner) stays rim.
//  - A descent after which the line is back at the level it left in fewer
//    points than a side has (a dip of the rim at a box's corner) ends
//    there: it does not take the rim up to the next side into its hole.
//  - A descent without its ascent (a line broken at the bottom of a hole)
//    ends where the line is back at the rim's level, or at the line's end;
//    such open halves are joined across lines when their low ends meet.
//  - A line that does not reach the top (a middle grasp) is a claw hole by
//    itself if it spans `min_segment_height_m` in z, else noise (a flat
//    loop, e.g. flagged bottom edges), as are lines shorter than
//    `min_line_points`.
//
// Pure and single-threaded.
#pragma once

#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Parameters of ClassifyBoundaries. Distances in meters, in V.
struct ClassifyConfig {
  /// Lines with fewer points are noise.
  int min_line_points{10};
  /// A line reaches the top when its highest point is within this of the
  /// highest boundary point. Covers a top rim tilted by a few degrees in V
  /// (a 10 cm rim at 3 degrees: +-2.6 mm); a middle grasp's holes end
  /// 2 cm or more below the top.
  double top_band_m{0.008};
  /// Reversals of z smaller than this do not end a monotone segment.
  double monotone_tolerance_m{0.002};
  /// A claw side has more than 5 points (the paper)...
  int min_segment_points{6};
  /// ... drops at least this much ...
  double min_segment_height_m{0.005};
  /// ... and its drop over its chord is at least this (a vertical side: 1;
  /// a 20 degree oblique finger: 0.94; a rim tilted by 5 degrees: 0.09).
  double min_segment_slope{0.5};
  /// Open claw halves whose low ends are closer than this are one hole.
  double merge_distance_m{0.01};
  /// Claw boundaries with fewer points are dropped as noise.
  int min_claw_points{10};

  /// Throws std::invalid_argument naming the first invalid field.
  void Validate() const;
};

/// Classifies `lines` (indices into `points_V`, the cloud in V [m]).
/// @return at most one HoleKind::kMissingSurface boundary, first (its open
///   pieces merged counter-clockwise around V's z-axis, closed only if it
///   is one closed line that no claw hole interrupts), then one kClaw
///   boundary per claw hole, ordered by the angle of their centroid around
///   V's z-axis (open where they meet the top, closed when isolated).
///   source_indices are the lines' indices. Empty when no line qualifies.
/// Non-finite points are dropped from the lines. Throws
/// std::invalid_argument on an invalid config or an index out of range.
/// Linear in the lines' length: ~0.05 ms for 1.3k boundary points.
std::vector<HoleBoundary> ClassifyBoundaries(const PointList& points_V,
                                             const std::vector<BoundaryLine>& lines,
                                             const ClassifyConfig& config);

}  // namespace graspfill::repair
