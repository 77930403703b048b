// SPDX-License-Identifier: BSD-3-Clause
// The top from the evidence (evidence_config.hpp): the height of a flat
// top where the rays grazing over it first carve its extruded outline, or
// a dome over a tapered one. Pure and single-threaded.
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <string>

#include "evidence_config.hpp"
#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/repair/repair_types.hpp"
#include "local_surfaces.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// How the evidence top came out.
enum class TopEvidence {
  kHeightFound,    ///< a carved ring above the wall fixed the height
  kNotObservable,  ///< no ring was carved: closed at the highest wall
  kNoOutline,      ///< too few points near the top for an outline
  kTapered,        ///< the walls close in towards the top: no flat cap
  kDome,           ///< tapered, closed by a dome fitted to the top band
};

/// A dome's surface (V): the height field over V's x-y that closes a
/// tapered top, or the quadric its points were moved onto. Its points take
/// their normals from it.
struct DomeSurface {
  fill::HeightField field;
  std::optional<fill::Quadric> quadric;
  /// The outward unit normal at `p_V`, a point of the dome.
  Eigen::Vector3f Normal(const Eigen::Vector3f& p_V) const;
};

struct EvidenceTop {
  TopEvidence outcome{TopEvidence::kNoOutline};
  float wall_top_z_V{0.0f};  ///< highest observed point [m]
  float top_z_V{0.0f};       ///< the top's height used [m]
  PointList added_V;         ///< band and cap, none in seen-free space
  /// A flat top's: how far the observed walls depart from a prism under
  /// it, the RMS distance in V's x-y from each height band's outline
  /// (top_band_m thick, down to the lowest point) to the top band's. An
  /// extrusion of the top's outline explains the walls within this [m].
  double extrusion_rms_m{std::numeric_limits<double>::infinity()};
  /// The vertices that describe the top band's hull (a flat top's
  /// outline) to within a spacing.
  int outline_vertices{0};
  int rejected_free{0};             ///< candidates dropped as seen free
  std::optional<DomeSurface> dome;  ///< a dome's surface (outcome kDome)
};

/// Closes the top of the cloud (`observed_V`'s points: observed, +z up in
/// V) at the height the evidence gives: a wall band on the top outline from
/// the highest observed point up to that height, and a cap there, sampled
/// at `spacing_m`, skipping places within 0.75 spacing of the cloud or of
/// `fills_V` (earlier fills) and any point the record sees free.
/// `dome_outcome_only`: a dome is only found, not sampled (no added_V):
/// for a caller that refits it over more points.
EvidenceTop CloseTopFromEvidence(const NeighborIndex& observed_V, const PointList& fills_V,
                                 const evidence::VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                                 double spacing_m, const EvidenceConfig& config,
                                 bool dome_outcome_only = false);

/// "height found", "not observable", "no outline", "tapered top", "dome".
std::string TopEvidenceName(TopEvidence outcome);

}  // namespace graspfill::repair
