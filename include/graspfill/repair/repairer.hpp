// The hole repair, chained: outliers, boundary points, boundary lines, the
// virtual frame V, classification into the missing surface and the claw
// holes, boundary completion, then the fills (claw holes from a local
// Poisson surface, the missing top by symmetry). Cui, Zhang & Wang, Sensors
// 2021, section 2; `kPaper` is the method as written (the tangent-plane
// eigenvector slip corrected), `kBest` is graspfill's default, which adds:
//  - steps 1-4 on ~8k voxel centroids for clouds above 25k points, the
//    boundary re-tested at full resolution only around what they show
//    (analysis_cloud.hpp): ~85 ms for 50k points instead of ~250-400;
//  - one kNN table shared by the outlier filter and the boundary test,
//    a median floor in the outlier filter, a 50-neighbour confirmation of
//    every boundary point;
//  - V's axis refined from the side normals (axis_refinement.hpp);
//  - the rim also taken from every boundary point near the top of V when
//    the linking breaks it (fused clouds);
//  - local surface fits for the claw holes (Poisson as the fallback), the
//    prism test and the outline checks of the symmetry plane.
// `graspfill bench repair` measures both against the paper's tables.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/repair/analysis_cloud.hpp"
#include "graspfill/repair/axis_refinement.hpp"
#include "graspfill/repair/boundary_classification.hpp"
#include "graspfill/repair/boundary_completion.hpp"
#include "graspfill/repair/boundary_detection.hpp"
#include "graspfill/repair/boundary_linking.hpp"
#include "graspfill/repair/claw_hole_repair.hpp"
#include "graspfill/repair/outlier_removal.hpp"
#include "graspfill/repair/symmetry_repair.hpp"
#include "graspfill/repair/virtual_frame.hpp"
#include "graspfill/types.hpp"

namespace graspfill::repair {

enum class RepairMode {
  kPaper,  ///< section 2 as written
  kBest,   ///< graspfill's default (see repairer.cpp for what differs)
};

struct RepairConfig {
  RepairMode mode{RepairMode::kBest};
  AnalysisConfig analysis;  ///< best mode only: the paper works on the input
  OutlierConfig outliers;
  BoundaryConfig boundary;
  LinkConfig link;
  VirtualFrameConfig frame;
  AxisRefineConfig axis;  ///< best mode only (the paper has no such step)
  ClassifyConfig classify;
  CompletionConfig completion;
  ClawRepairConfig claw;
  SymmetryConfig symmetry;
  /// Best mode: boundary points within this of the top of V [m] form the
  /// missing surface's rim when step 5's is smaller (0: step 5's only; the
  /// paper). 4 mm: a fused cloud's rim band, ~3 voxels.
  double top_rim_band_m{0.004};
  /// Optional hint of the object's "up" (towards the missing top) in the
  /// input frame; never required.
  std::optional<Eigen::Vector3d> up_hint;

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

struct RepairReport {
  /// "repaired", "no holes found" (the cloud comes back unchanged), or why
  /// nothing could be repaired ("too few points", "no virtual frame: ...").
  std::string status;
  bool symmetric{false};        ///< a symmetry plane was found and used
  std::string symmetry_reason;  ///< why not, when !symmetric
  int outliers_ignored{0};      ///< kept in the output, not used to repair
  int boundary_points{0};
  int boundary_lines{0};
  VirtualFrame frame;           ///< valid when status == "repaired"
  std::vector<HoleSummary> holes;  ///< boxes in the input frame
  std::vector<StageTiming> timings;
};

struct RepairResult {
  /// Every input point unchanged (same order, provenance as given), then
  /// the added points with their provenance (surface / symmetry).
  ObjectCloud cloud;
  RepairReport report;
};

/// Repairs an unorganized cloud (meters, any pose, normals optional: when
/// given they are kept and the added points get estimated ones, oriented
/// away from the centroid; otherwise the output has none). Throws std::invalid_argument on non-finite coordinates or a
/// bad config; a cloud too small or without holes comes back unchanged
/// with the reason in report.status.
RepairResult Repair(const ObjectCloud& input, const RepairConfig& config = {});

}  // namespace graspfill::repair
