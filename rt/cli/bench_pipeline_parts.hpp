// SPDX-License-Identifier: BSD-3-Clause
// The pieces `bench repair --pipeline` (the shape zoo) and `bench repair
// --objects` (scanned meshes) share: a synthetic scene through the whole
// pipeline, the repair timed over repeats that must agree, and the
// measurements of a repaired cloud against the truth.
#pragma once

#include <cstddef>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/pipeline/pipeline.hpp"
#include "graspfill/repair/repairer.hpp"
#include "graspfill/types.hpp"
#include "synth/scene.hpp"

namespace graspfill::cli {

/// Coverage is the share of the truth within this of a cloud [m].
constexpr double kCoverageRadiusM = 0.002;
/// An added point farther than this from the truth is "wrong" [m].
constexpr double kWrongDistanceM = 0.003;

/// Every frame of `scene` rendered, sent through the wire format (so that
/// depth is quantized as in a recording) and fed with the gripper states
/// in time order to a pipeline with `config` and the scene's claw; flushed.
/// @throws std::runtime_error when a frame does not decode,
///   std::invalid_argument on a bad config.
std::unique_ptr<Pipeline> RunSceneThroughPipeline(const synth::Scene& scene, const PipelineConfig& config);

/// The truth the benchmarks measure against: 200,000 samples of the
/// object's surface in G (seed 5, whatever the scene's seed).
mesh::SurfaceSamples TruthSamples(const synth::Scene& scene);

/// A fused cloud against the truth.
struct FusedMeasures {
  double coverage{0.0};  ///< share of the truth within kCoverageRadiusM
  double p95_mm{0.0};    ///< of its points' distances to the truth
  double p99_mm{0.0};
  double off_object_share{0.0};  ///< share of its points > kWrongDistanceM from the truth
};

/// `fused` (not empty) against `truth`.
FusedMeasures MeasureFused(const ObjectCloud& fused, const std::vector<Eigen::Vector3f>& truth);

/// A repaired cloud against the truth.
struct Outcome {
  size_t points{0};
  size_t added{0};
  double coverage{0.0};      ///< share of the truth within kCoverageRadiusM
  double added_p95_mm{0.0};  ///< 0 when nothing was added
  double added_wrong{0.0};   ///< share of the added points > kWrongDistanceM
  /// The added points the repair stands behind (confidence > 0.5, more
  /// likely right than not), their p95 and share > kWrongDistanceM (0 when
  /// none): what a planner that keeps only those would be given.
  size_t trusted_added{0};
  double trusted_p95_mm{0.0};
  double trusted_wrong{0.0};
  int added_in_free{0};  ///< added points in seen-free space
  /// Share of the truth outside the cloud's safe bound, the planner's
  /// keep-out (NaN: the cloud carries none): the bound must hold the whole
  /// object, the unseen top and what the claw hid included.
  double truth_outside_bound{0.0};
  double ms{0.0};              ///< the fastest repair
  std::string note;            ///< RepairNote of the report
  std::string top_completion;  ///< the report's (what won the top's search)
  float top_confidence{0.0f};
  std::vector<StageTiming> steps;  ///< the fastest repair's steps
  repair::EvidenceReport evidence;
  Eigen::Vector3d up_axis{Eigen::Vector3d::Zero()};  ///< V's +z in G (0 when not repaired)
};

/// Coverage and the added points' errors of `cloud` (its first `fused`
/// points the observed ones) against `truth`.
Outcome Measure(const ObjectCloud& cloud, size_t fused, const std::vector<Eigen::Vector3f>& truth,
                const evidence::VisibilityRecord& record);

/// A repair of a fused cloud as `replay` does it (rt::RepairObjectCloud
/// with rt::GripperFrameRepairConfig()), run `repeat` times.
struct TimedRepair {
  ObjectCloud cloud;  ///< the first run's
  repair::RepairReport report;
  double best_ms{0.0};
  std::vector<StageTiming> best_steps;
};

/// `record` null: from the cloud alone. The fastest of `repeat` runs is
/// timed (a shared machine's times move by tens of % between runs).
/// @throws std::runtime_error when a run's cloud differs from the first's.
TimedRepair RepairTimed(const ObjectCloud& fused, const evidence::VisibilityRecord* record, int repeat);

/// The report's status, and what the repair refused or left open.
std::string RepairNote(const repair::RepairReport& report);

/// The repair's steps and their times: " outliers 12.3 boundary_points 4.5 ...".
std::string StepsText(const std::vector<StageTiming>& steps);
nlohmann::ordered_json StepsJson(const std::vector<StageTiming>& steps);

/// Checks --dump's folder before any work: a directory, and none of
/// `paths` there already (nothing is overwritten).
/// @return "" or the problem, naming the path.
std::string CheckDumpPaths(const std::string& dump_dir, const std::vector<std::string>& paths);

}  // namespace graspfill::cli
