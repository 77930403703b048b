// SPDX-License-Identifier: BSD-3-Clause
// Step 3 of the hole repair (Cui et al. 2021, section 2.2.2): the unordered
// boundary points chained into ordered, closed boundary lines.
//
// The paper's rule: a chain links its last point P2 to a nearby boundary
// point P, and among the nearest candidates takes the one with the smallest
// deflection angle theta(P) = angle(P1P2, P2P) (Eq. 3), so that it follows
// its own rim past a second, close hole instead of jumping across
// ("adhesion", Fig. 6); unclosed and isolated chains are dropped. Here:
// - Candidates are the `candidates` nearest free boundary points within
//   reach (max_link_factor local spacings) and within max_deflection_rad;
//   those up to 2x as far as the nearest compete on theta. P1 is taken 3
//   links back: the detector flags a band 1-3 points wide along a rim and
//   the last link alone zig-zags across it.
// - Free points near each link (absorb_factor spacings) are consumed with
//   it, else the rest of the band would make parallel, duplicate lines.
// - With the detector's BoundaryPointInfo (recommended), a candidate whose
//   gap direction (the side its hole is on) turns more than 90 degrees from
//   the chain's, or puts the hole on the chain's other hand, is refused:
//   that is what keeps two holes a few spacings apart separate (Eq. 3 alone
//   fails where a rim curves into the neck and the other hole's rim runs
//   straight on), and what stops a chain folding back along its own band.
//   The info also gives the cloud's local spacing; without it the spacing
//   is estimated from the boundary points (half the distance to the 4th
//   nearest one).
// - A dead end is first bridged: 2x the reach, straight on only (half the
//   deflection limit); random samples leave gaps in a flagged rim. If that
//   fails the chain backs up one point at a time (they stay consumed) and
//   tries again: a false boundary branching from a rim (a sharp edge the
//   detector flags, e.g. a triangular prism's vertical edges below the cut
//   top) is cut off that way. If no earlier point goes anywhere either, the
//   chain is restored and grows from its other end.
// - The chain closes when it comes back within reach of its own points at
//   least min_points - 1 links back, when that is no farther than the way
//   on (the earliest such point is taken: the longest loop); onto a point
//   other than its first only if the loop is at least 4 reaches long (a
//   tail joining a rim, not a squiggle at a corner). Whatever precedes the
//   loop is a tail and is dropped. A loop must enclose >= 4 squared
//   spacings. A chain that fails gives its points back (bounded) so that it
//   cannot starve the chain of the hole it wandered over.
//
// Measured (boundary_linking_test.cc, with the detector's info): a plane
// with a hole gives one ring around it (20/20 random samples) and one around
// the outer edge; two 8 mm holes 3 spacings apart give two rings in 19/20
// samples (9/20 without the info: Eq. 3 alone); each of the six paper
// shapes (three seeds each) gives exactly one closed line.
//
// In the paper's setting the claw holes touch the missing top, so a single
// closed line runs around the top and in and out of each claw hole: that is
// expected (step 5, classification, splits it). A gap in a rim wider than
// twice the reach leaves that rim with no line.
#pragma once

#include <cmath>
#include <vector>

#include "boundary_detection.hpp"
#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Parameters of the linking. Lengths are in units of the local point
/// spacing (see the file comment), so they hold at any scale.
struct LinkConfig {
  /// Free boundary points within reach considered for the next link, the
  /// nearest first (the paper's "nearest neighbour points P and Q").
  int candidates{6};
  /// Reach: no ordinary link longer than this many local spacings (a
  /// bridge over a gap may take twice as much). 3 covers the irregular
  /// spacing of a random sample's flagged rim.
  double max_link_factor{3.0};
  /// Lines with fewer points are dropped (the paper's isolated boundaries);
  /// also the least number of links before a chain may close on itself.
  int min_points{10};
  /// Largest deflection angle theta (Eq. 3) of a link [rad]. P1 lags 3
  /// links behind, so a rim's corner shows up whole in one link: 90
  /// degrees at a claw hole's corner, 120 at a triangular prism's edge,
  /// plus the band's scatter; 3*pi/4 lets those through (2*pi/3 broke the
  /// paper cylinder's claw-hole corners where the band is deep).
  double max_deflection_rad{0.75 * M_PI};
  /// Free points within this many local spacings of a link are consumed
  /// with it (they are the same rim's band).
  double absorb_factor{1.5};

  /// Throws std::invalid_argument unless candidates >= 1, min_points >= 3,
  /// 0 < absorb_factor < max_link_factor and max_deflection_rad in (0, pi].
  void Validate() const;
};

/// Chains the boundary points `boundary_indices` (indices into `points`,
/// e.g. from DetectBoundaryPoints; duplicates ignored) into closed lines.
/// `info`, if given, is DetectBoundaryPoints' info for the same points (same
/// order); without it the linking is the paper's Eq. 3 alone and close holes
/// may adhere. Each line's indices refer to `points` and are in linking
/// order; its last point links back to its first (closed is always true).
/// Deterministic. Builds one small KD-tree over the boundary points only.
/// Throws std::invalid_argument on an invalid config, an index out of range
/// or an info of the wrong size.
std::vector<BoundaryLine> LinkBoundaryPoints(const PointList& points,
                                             const std::vector<int>& boundary_indices,
                                             const LinkConfig& config,
                                             const std::vector<BoundaryPointInfo>* info = nullptr);

}  // namespace graspfill::repair
