// SPDX-License-Identifier: BSD-3-Clause
// `graspfill bench`'s integrators side by side (issue 39, "the
// integrator"): Open3D's legacy ScalableTSDFVolume (the product's volume,
// integrated by Open3D's own call: fusion::TsdfFusion::IntegrateUncached)
// and its tensor VoxelBlockGrid
// (fusion/voxel_block_grid_fusion.hpp), each at 16^3 and 8^3 voxels a
// block, fed the very frames the pipeline fused, at the product's voxel
// and truncation, each frame timed; a cloud from each over its whole
// volume every few frames, timed; the final clouds compared with the
// product's.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fusion/voxel_block_grid_fusion.hpp"
#include "graspfill/core/stage_timer.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"
#include "graspfill/types.hpp"

namespace graspfill::cli {

/// One integrator's measurements.
struct IntegratorRun {
  std::string name;  ///< e.g. "VoxelBlockGrid 8^3"
  StageTotal integrate;
  /// A cloud over the whole volume (Open3D's extraction, sorted as the
  /// product sorts) every IntegratorComparison::kExtractEvery frames [ms].
  std::vector<double> extract_ms;
  ObjectCloud cloud;  ///< after the last frame (Finish)
};

class IntegratorComparison {
 public:
  static constexpr int kExtractEvery = 3;

  /// Every integrator at `tsdf`'s voxel and truncation; their OpenMP
  /// regions on at most `num_threads` threads (core/openmp_threads.hpp).
  IntegratorComparison(const fusion::TsdfConfig& tsdf, int num_threads);
  ~IntegratorComparison();
  IntegratorComparison(const IntegratorComparison&) = delete;
  IntegratorComparison& operator=(const IntegratorComparison&) = delete;

  /// One frame (cropped and masked, in the volume's frame V) into each.
  void Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_V);
  /// Each one's cloud after the last frame, into runs()[i].cloud.
  void Finish();

  /// ScalableTSDFVolume at the product's block size ([0]) and at the
  /// other of 16^3 and 8^3, then VoxelBlockGrid at the same two.
  const std::vector<IntegratorRun>& runs() const { return runs_; }
  int num_threads() const { return num_threads_; }

 private:
  void Extract(size_t i, ObjectCloud* cloud) const;

  int num_threads_;
  int frames_{0};
  std::vector<std::unique_ptr<fusion::TsdfFusion>> scalable_;
  std::vector<std::unique_ptr<fusion::VoxelBlockGridFusion>> grids_;
  std::vector<IntegratorRun> runs_;
};

/// Percentile(v, q), 0 when v is empty (nothing measured, e.g. no cloud
/// taken from fewer than kExtractEvery frames).
double PercentileOr0(const std::vector<double>& v, double q);

/// Nearest distances from one cloud to another [mm].
struct DistancesMm {
  double p50{0.0}, p95{0.0}, p99{0.0}, max{0.0};
};

/// One integrator's row of the bench: [0] at 1 thread, [1] at 2 (when
/// measured).
struct IntegratorRow {
  std::string name;
  int64_t frames{0};
  double integrate_ms[2]{};
  double extract_p50_ms[2]{}, extract_p99_ms[2]{};  ///< 0: no cloud taken
  double integrate_over_product{0.0};               ///< at 1 thread, over row 0's
  size_t points{0};                                 ///< the final cloud's, at 1 thread
  /// The final cloud to the product's (row 0) and back (row 0: 0; all 0
  /// when either cloud is empty).
  DistancesMm to_product, from_product;
  /// The final cloud against the object's truth, when there is one: the
  /// share of the truth within 2 mm of the cloud, and the cloud's p95
  /// distance to the truth [mm] (eval::Compare).
  double truth_coverage_2mm{0.0}, truth_p95_mm{0.0};
};

struct IntegratorSummary {
  std::vector<IntegratorRow> rows;  ///< as IntegratorComparison::runs()
  bool two_threads{false};          ///< the rows' [1] measured
  bool truth{false};                ///< the rows' truth_* measured
  /// Every integrator's final cloud the same at 2 threads as at 1.
  bool same_clouds_at_both_thread_counts{false};
};

/// The rows of `one` and of `two` (the same frames at 2 threads; null:
/// not measured), both finished; `truth` (null: none) the object's
/// surface in the volume's frame.
IntegratorSummary Summarize(const IntegratorComparison& one, const IntegratorComparison* two,
                            const ObjectCloud* truth);
/// The summary's table on stdout, and as JSON.
void PrintIntegratorTable(const IntegratorSummary& summary);
nlohmann::ordered_json IntegratorJson(const IntegratorSummary& summary);

}  // namespace graspfill::cli
