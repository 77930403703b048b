// SPDX-License-Identifier: BSD-3-Clause
// The repair's evidence stage (Repair, best mode, with a record): whether
// the record given is one to use, and the evidence's part of steps 7-8.
// It composes the record's point-list queries (evidence/
// point_list_queries.hpp), the mirror's lowering and lift
// (mirror_evidence.hpp) and the top from the evidence (evidence_top.hpp)
// with the claw fills and the mirror image. Internal to graspfill_repair.
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <optional>

#include "evidence_config.hpp"
#include "evidence_top.hpp"
#include "graspfill/evidence/visibility_record.hpp"
#include "neighbor_index.hpp"
#include "repair_steps.hpp"
#include "symmetry_repair.hpp"

namespace graspfill::repair {

// The record, if it is given, non-empty and of this cloud (its observed
// points are not in its free space); else null with the reason reported.
const evidence::VisibilityRecord* UsableRecord(const ObjectCloud& input,
                                               const evidence::VisibilityRecord* record,
                                               const RepairSettings& config, EvidenceReport* report);

// The evidence's top: its points (V), how it came out, and how many of
// its proposed points the record saw free or in the claw; beside it, for
// a flat top, its whole lid (the top's outline at the rays' height, over
// the mirror's image or not) for the search's extrusion.
struct EvidenceTopPoints {
  PointList points_V;
  TopEvidence outcome{TopEvidence::kNoOutline};
  int rejected{0};
  PointList extrusion_V;                                            ///< not yet tested against the claw
  int extrusion_rejected{0};                                        ///< seen free
  double extrusion_rms_m{std::numeric_limits<double>::infinity()};  ///< EvidenceTop's
  int outline_vertices{0};                                          ///< EvidenceTop's
  std::optional<DomeSurface> dome;                                  ///< the surface of points_V, when a dome
};

// The evidence's part of steps 7-8: fills in seen-free space dropped, a
// contradicted mirror refused, and the top closed at the height the rays
// give unless the mirror's top holds. `index_V` is over the observed points
// (V), `surface_V` the claw fills.
EvidenceTopPoints ApplyEvidence(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                                const Eigen::Isometry3f& T_in_V, const NeighborIndex& index_V,
                                double spacing_m, PointList* surface_V, SymmetryResult* symmetry,
                                EvidenceReport* report);

}  // namespace graspfill::repair
