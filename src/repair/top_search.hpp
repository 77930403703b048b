// SPDX-License-Identifier: BSD-3-Clause
// The missing top, chosen by one scored search (the idea of Bohg et al.
// 2011, "Mind the gap": complete by a hypothesis, then judge it by the
// evidence). Each completion the steps propose for the side the camera
// never saw, and "leave it open", gets one cost, lower is better:
//
//   cost = 1/2 (seal / sigma)^2 + 1/2 (free / epsilon)^2 + p ln(n) / (2 n)
//
//  - seal: how well the completion meets the observed surface where the
//    hole begins: the median distance from the hole's n rim points to the
//    nearest added point (a claw fill counts; the median, so that a claw's
//    mouth the rim runs across does not sink a completion that meets the
//    rest). sigma is the cloud's own spacing: a completion sampled a
//    spacing apart, and right, meets the rim within one or two.
//  - free: the share of its proposed points a ray passed through (seen-
//    free space, or inside the claw); epsilon = 2%, what a right one
//    shows from the record's noise.
//  - p ln(n) / (2 n): the complexity prior (BIC per rim point), p the
//    completion's free parameters.
//  - "open" adds nothing and costs 1/2 3^2: a completion must meet the rim
//    within 3 sigma to beat it.
//
// The cheapest wins; its confidence is its posterior against the runner-
// up, 1 / (1 + exp(-margin)). A flat cap is proposed only as a prism's
// lid, where the top's outline explains the walls all the way down (the
// extrusion): the top band's walls alone cannot tell a can's lid from a
// cup's mouth, but a cup narrows to its bottom.
//
// Frames and units: points in V [m]. Pure, single-threaded, deterministic.
#pragma once

#include <string>
#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

enum class TopFamily {
  kOpen,        ///< nothing added: the top stays unobserved
  kMirror,      ///< the mirror image of the far end (symmetry_repair.hpp)
  kRevolution,  ///< a surface of revolution that closes (revolution_fill.hpp)
  kDome,        ///< a quadratic dome over a tapered top (evidence_top.hpp)
  kExtrusion,   ///< the top's outline extruded to the rays' height (evidence_top.hpp)
};

/// "Open" costs what a completion meeting the rim at this many sigma does;
/// a model that misses the seen surface by more (RMS) is not proposed.
inline constexpr double kOpenSigmas = 3.0;

/// "open", "mirror", "revolution", "dome", "extrusion".
std::string TopFamilyName(TopFamily family);

struct TopCandidate {
  TopFamily family{TopFamily::kOpen};
  PointList points_V;  ///< what it adds, after the record's tests
  /// The points its seal is measured on, when not points_V: a model
  /// sampled where the cloud leaves a spacing open, as the mirror's image.
  PointList seam_V;
  /// The model's own normals of points_V (V), where it has a surface to
  /// give them; empty otherwise (estimated from the neighbours).
  std::vector<Eigen::Vector3f> normals_V;
  int parameters{0};       ///< its free parameters (the complexity prior)
  double free_share{0.0};  ///< of its proposed points, seen free or in the claw
  double seal_m{0.0};      ///< set by ChooseTop
  double cost{0.0};        ///< set by ChooseTop
};

struct TopChoice {
  std::vector<TopCandidate> candidates;  ///< as given, then "open", scored
  size_t best{0};
  /// The best's posterior against the runner-up, in [0.5, 1) (0.5 when
  /// "open" was the only one).
  float confidence{0.5f};
  const TopCandidate& Best() const { return candidates[best]; }
};

/// Scores `candidates` and "open" against the rim (`rim_V`, the missing
/// top's boundary points) and the claw fills (`fills_V`), at the cloud's
/// spacing `spacing_m`; the first of equal costs wins.
TopChoice ChooseTop(std::vector<TopCandidate> candidates, const PointList& rim_V, const PointList& fills_V,
                    double spacing_m);

}  // namespace graspfill::repair
