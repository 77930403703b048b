// SPDX-License-Identifier: BSD-3-Clause
// The hole repair, chained: outliers, boundary points, boundary lines, the
// virtual frame V, classification into the missing surface and the claw
// holes, boundary completion, then the fills (claw holes from a local
// Poisson surface, the missing top by symmetry). Cui, Zhang & Wang, Sensors
// 2021, section 2; `kPaper` is the method as written (the tangent-plane
// eigenvector slip corrected), `kBest` is graspfill's default, which adds:
//  - steps 1-4 on ~8k voxel centroids for clouds above 25k points, the
//    boundary re-tested at full resolution only around what they show:
//    ~85 ms for 50k points instead of ~250-400;
//  - one kNN table shared by the outlier filter and the boundary test,
//    a median floor in the outlier filter, a 50-neighbour confirmation of
//    every boundary point;
//  - V's axis refined from the side normals;
//  - the rim also taken from every boundary point near the top of V when
//    the linking breaks it (fused clouds);
//  - local surface fits for the claw holes (a thin-plate spline over the
//    rim where no fit explains it; the paper's Poisson only in kPaper), the
//    prism test and the outline checks of the symmetry plane;
//  - with the camera's evidence, the top chosen by a scored search among
//    the mirror, revolution, dome, extrusion and "open" (docs/repair-method.md).
// `graspfill bench repair` measures both against the paper's tables.
//
// The steps live in src/repair/, one file each, with their own settings at
// documented defaults; RepairConfig holds what a caller chooses.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/repair/repair_types.hpp"
#include "graspfill/types.hpp"

namespace graspfill::repair {

enum class RepairMode {
  kPaper,  ///< section 2 as written
  kBest,   ///< graspfill's default (see repairer.cpp for what differs)
};

/// What a caller of the repair chooses; every step's own settings are the
/// library's (src/repair/, at the defaults their headers document).
struct RepairConfig {
  RepairMode mode{RepairMode::kBest};
  /// With a visibility record: the planner's safe bound's voxel edge [m]
  /// (0: no bound).
  double safe_bound_voxel_m{0.005};
  /// Best mode: boundary points within this of the top of V [m] form the
  /// missing surface's rim when step 5's is smaller (0: step 5's only; the
  /// paper's, whatever is set here). 4 mm: a fused cloud's rim band, ~3
  /// voxels.
  double top_rim_band_m{0.004};
  /// Optional hint of the object's "up" (towards the missing top) in the
  /// input frame; never required.
  std::optional<Eigen::Vector3d> up_hint;
  /// OpenMP threads of the call (the libraries it uses; the repair's own
  /// steps are single-threaded): 1 (default) the calling thread alone, N > 1
  /// at most N, 0 OpenMP's own count. Applied for the call and the caller's
  /// settings restored after it (core/openmp_threads.hpp).
  int num_threads{1};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// What the camera's evidence did (all zero / empty without a record).
struct EvidenceReport {
  /// The record was given, matched the cloud and was used.
  bool used{false};
  /// Why it was not used, when given ("empty", "does not match ...").
  std::string ignored_reason;
  int key_frames{0};
  /// Share of the observed points the record sees free (a matching
  /// record: < 1%).
  double observed_free_share{0.0};
  /// Share of the mirror image in seen-free space, of its points not
  /// beside the observed ones (within 4 mm of an observed point at least
  /// as high), after any lowering (NaN when no mirror).
  double mirror_free_share{0.0};
  /// How far the symmetry plane was lowered to take the mirror's top out of
  /// seen-free space (at most 4 mm) [m].
  double mirror_plane_drop_m{0.0};
  /// How far the mirror image's cap was raised, its top band stretched:
  /// to where the rays carve it, or to the rings' top when that decides
  /// (src/repair/evidence_config.hpp says when) [m].
  double mirror_lift_m{0.0};
  /// Proposed points dropped as seen free, over all fills.
  int rejected_free{0};
  /// Claw-hole fill points that lay inside the claw, moved onto its face
  /// (the finger touches the object there); other fills' points inside
  /// the claw, dropped.
  int moved_out_of_claw{0};
  int rejected_in_claw{0};
  /// The top: "height found", "not observable", "no outline", or "" when
  /// not tried (no record, or the mirror's top held).
  std::string top;
  float top_above_wall_m{0.0f};  ///< the top's height over the highest wall
  int top_points_added{0};
  /// Voxels in the safe bound and its grid.
  int safe_bound_voxels{0};
};

/// How a repair ended.
enum class RepairStatus {
  kRepaired,      ///< holes found (or the evidence's top closed) and filled
  kNoHoles,       ///< nothing to repair: the cloud comes back unchanged
  kTooFewPoints,  ///< below the steps' minimum: unchanged
  kNoFrame,       ///< no virtual frame could be found: unchanged
  kOutOfRange,    ///< beyond the documented limits (kMaxRepairPoints, extent): unchanged
};

/// The repair's input limits (docs/input-limits-and-fuzzing.md): the most points, and
/// the bulk's extent (RobustBox's largest side; stray points beyond it are
/// ignored as outliers) [m].
constexpr size_t kMaxRepairPoints = 4'000'000;
constexpr double kMinRepairExtentM = 1e-3;
constexpr double kMaxRepairExtentM = 10.0;

/// "repaired", "no holes found", "too few points", "no virtual frame",
/// "outside the repair's limits".
std::string RepairStatusName(RepairStatus status);

struct RepairReport {
  RepairStatus status{RepairStatus::kNoHoles};
  /// Why, for kTooFewPoints, kNoFrame and kOutOfRange (empty otherwise).
  std::string status_detail;
  /// The status's name, then the detail after ": " when there is one (what
  /// the CLI prints and `--json` gives as "status").
  std::string StatusText() const;
  bool symmetric{false};  ///< a symmetry plane was found and used
  /// Best mode: how the missing top was completed ("mirror", "revolution",
  /// "dome", "extrusion", or "open": nothing known there, nothing added), and the
  /// confidence of its points (the search's posterior, top_search.hpp; at
  /// most 0.5 for a lid over straight walls, which no view saw).
  std::string top_completion;
  float top_confidence{0.0f};
  std::string symmetry_reason;  ///< why not, when !symmetric
  int outliers_ignored{0};      ///< kept in the output, not used to repair
  /// Claw holes left open: no surface explains them (the thin-plate spline
  /// included) or their support is most of the cloud.
  int claw_holes_left_open{0};
  int boundary_points{0};
  int boundary_lines{0};
  VirtualFrame frame;              ///< valid when status == kRepaired
  std::vector<HoleSummary> holes;  ///< boxes in the input frame
  EvidenceReport evidence;
  std::vector<StageTiming> timings;
};

struct RepairResult {
  /// Every input point unchanged (same order, provenance as given), then
  /// the added points with their provenance (surface / symmetry). Its
  /// `holes` are this repair's (report.holes; the input's are replaced), so
  /// the cloud can be published as it is.
  ObjectCloud cloud;
  RepairReport report;
};

/// Repairs an unorganized cloud (meters, any pose, normals optional: when
/// given they are kept and the added points get normals too: a mirrored
/// point its source's, mirrored; a point on a fitted surface (the surface
/// of revolution, the dome) that surface's; the others a plane through
/// their neighbours', oriented away from the centroid; without input
/// normals the output has none). Throws std::invalid_argument on non-finite
/// coordinates or a bad config; a cloud too small or without holes comes back unchanged with the reason in
/// report.status and report.status_detail.
///
/// `record` (optional, best mode): what the camera saw, in the input's
/// frame (Pipeline::visibility() for a fused cloud in G). With it no added
/// point lies in seen-free space, a mirror image that contradicts it is
/// refused, the top closes at the height the evidence gives (also when the
/// cloud shows no hole), and the output carries the safe bound. A record
/// that does not match the cloud (most observed points in its free space)
/// or is empty is ignored and the report says why.
///
/// Confidence of the output points: observed 1; claw-hole fills 0.6
/// (0.8 where the record says the claw hid the spot); the missing top's
/// points the posterior of the completion that won the search against the
/// runner-up (report.top_confidence, 0.5-1; paper mode 0.5). A lid over
/// walls that run straight up to the rim (the extrusion's, or the mirror's
/// over a constant cross-section) carries at most 0.5: no view saw it, and
/// a mouth would end the walls alike. Above 0.5: the repair stands behind
/// the point. Where "open" won, nothing is added there and the report's
/// missing-surface hole is `unobserved`: the safe bound covers it.
RepairResult Repair(const ObjectCloud& input, const RepairConfig& config = {},
                    const evidence::VisibilityRecord* record = nullptr);

}  // namespace graspfill::repair
