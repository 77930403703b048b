// SPDX-License-Identifier: BSD-3-Clause
#include "bench_integrators.hpp"

#include <chrono>
#include <cstdio>
#include <string>

#include "eval/metrics.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill::cli {
namespace {

std::string Name(const char* integrator, int block_resolution) {
  return std::string(integrator) + " " + std::to_string(block_resolution) + "^3";
}

DistancesMm NearestDistancesMm(const ObjectCloud& from, const ObjectCloud& to) {
  if (from.size() == 0 || to.size() == 0) return {};
  const std::vector<double> d = mesh::NearestDistances(from.points_G, to.points_G);
  return {1e3 * Percentile(d, 50), 1e3 * Percentile(d, 95), 1e3 * Percentile(d, 99),
          1e3 * Percentile(d, 100)};
}

nlohmann::ordered_json Json(const DistancesMm& d) {
  return {{"p50", d.p50}, {"p95", d.p95}, {"p99", d.p99}, {"max", d.max}};
}

}  // namespace

double PercentileOr0(const std::vector<double>& v, double q) { return v.empty() ? 0.0 : Percentile(v, q); }

IntegratorComparison::IntegratorComparison(const fusion::TsdfConfig& tsdf, int num_threads)
    : num_threads_(num_threads) {
  CheckOpenMpThreads("IntegratorComparison num_threads", num_threads);
  // The product's block size first, then the other of Open3D's usual two:
  // a faster VoxelBlockGrid at a smaller block might owe it to the block.
  const int block_resolutions[] = {tsdf.block_resolution, tsdf.block_resolution == 8 ? 16 : 8};
  for (const int block_resolution : block_resolutions) {
    fusion::TsdfConfig config = tsdf;
    config.block_resolution = block_resolution;
    scalable_.push_back(std::make_unique<fusion::TsdfFusion>(config));
    runs_.push_back({Name("ScalableTSDFVolume", block_resolution), {}, {}, {}});
  }
  for (const int block_resolution : block_resolutions) {
    grids_.push_back(std::make_unique<fusion::VoxelBlockGridFusion>(
        fusion::VoxelBlockGridConfig::Like(tsdf, block_resolution)));
    runs_.push_back({Name("VoxelBlockGrid", block_resolution), {}, {}, {}});
  }
}

IntegratorComparison::~IntegratorComparison() = default;

void IntegratorComparison::Extract(size_t i, ObjectCloud* cloud) const {
  if (i < scalable_.size()) {
    scalable_[i]->ExtractCloudUncached(cloud);
  } else {
    grids_[i - scalable_.size()]->ExtractCloud(cloud);
  }
}

void IntegratorComparison::Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_V) {
  const ScopedOpenMpThreads threads(num_threads_);
  for (size_t i = 0; i < scalable_.size(); ++i) {
    ScopedStageTimer t(&runs_[i].integrate);
    scalable_[i]->IntegrateUncached(frame, T_C_V);  // Open3D's own call
  }
  for (size_t g = 0; g < grids_.size(); ++g) {
    ScopedStageTimer t(&runs_[scalable_.size() + g].integrate);
    grids_[g]->Integrate(frame, T_C_V);
  }
  if (++frames_ % kExtractEvery != 0) return;
  for (size_t i = 0; i < runs_.size(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    Extract(i, &runs_[i].cloud);
    runs_[i].extract_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
}

void IntegratorComparison::Finish() {
  const ScopedOpenMpThreads threads(num_threads_);
  for (size_t i = 0; i < runs_.size(); ++i) Extract(i, &runs_[i].cloud);
}

IntegratorSummary Summarize(const IntegratorComparison& one, const IntegratorComparison* two,
                            const ObjectCloud* truth) {
  IntegratorSummary summary;
  summary.two_threads = two != nullptr;
  summary.truth = truth != nullptr && truth->size() > 0;
  summary.same_clouds_at_both_thread_counts = summary.two_threads;
  const ObjectCloud& product = one.runs()[0].cloud;
  for (size_t i = 0; i < one.runs().size(); ++i) {
    const IntegratorRun& run = one.runs()[i];
    IntegratorRow row;
    row.name = run.name;
    row.frames = run.integrate.count;
    for (int k = 0; k < (two != nullptr ? 2 : 1); ++k) {
      const IntegratorRun& r = k == 0 ? run : two->runs()[i];
      row.integrate_ms[k] = r.integrate.mean_ms();
      row.extract_p50_ms[k] = PercentileOr0(r.extract_ms, 50);
      row.extract_p99_ms[k] = PercentileOr0(r.extract_ms, 99);
    }
    const double product_ms = one.runs()[0].integrate.mean_ms();
    row.integrate_over_product = product_ms > 0.0 ? row.integrate_ms[0] / product_ms : 0.0;
    row.points = run.cloud.size();
    if (i > 0) {
      row.to_product = NearestDistancesMm(run.cloud, product);
      row.from_product = NearestDistancesMm(product, run.cloud);
    }
    if (summary.truth && run.cloud.size() > 0) {
      const eval::CloudMetrics m = eval::Compare(run.cloud.points_G, truth->points_G);
      row.truth_coverage_2mm = m.coverage_2mm;
      row.truth_p95_mm = m.p95_pred_to_gt_mm;
    }
    if (two != nullptr) {
      const ObjectCloud& at_two = two->runs()[i].cloud;
      summary.same_clouds_at_both_thread_counts = summary.same_clouds_at_both_thread_counts &&
                                                  run.cloud.points_G == at_two.points_G &&
                                                  run.cloud.normals_G == at_two.normals_G;
    }
    summary.rows.push_back(row);
  }
  return summary;
}

void PrintIntegratorTable(const IntegratorSummary& summary) {
  const std::vector<IntegratorRow>& rows = summary.rows;
  std::printf(
      "Open3D's integrators on the same %lld frames: integration per frame [ms] (and over the product's), "
      "a cloud of the whole volume every %d frames p50 / p99 [ms]\n",
      static_cast<long long>(rows[0].frames), IntegratorComparison::kExtractEvery);
  std::printf("%-34s %12s %8s %15s", "", "1 thread", "", "");
  if (summary.two_threads) std::printf(" %12s %15s", "2 threads", "");
  std::printf("\n%-34s %12s %8s %15s", "", "integrate", "ratio", "cloud");
  if (summary.two_threads) std::printf(" %12s %15s", "integrate", "cloud");
  std::printf("\n");
  for (const IntegratorRow& r : rows) {
    std::printf("%-34s %12.3f %8.2f %7.2f / %5.2f", r.name.c_str(), r.integrate_ms[0],
                r.integrate_over_product, r.extract_p50_ms[0], r.extract_p99_ms[0]);
    if (summary.two_threads) {
      std::printf(" %12.3f %7.2f / %5.2f", r.integrate_ms[1], r.extract_p50_ms[1], r.extract_p99_ms[1]);
    }
    std::printf("\n");
  }
  std::printf("final clouds beside %s's (%zu points), nearest distance p50 / p95 / p99 / max [mm]:\n",
              rows[0].name.c_str(), rows[0].points);
  for (size_t i = 1; i < rows.size(); ++i) {
    const DistancesMm& to = rows[i].to_product;
    const DistancesMm& from = rows[i].from_product;
    std::printf("  %s: %zu points; to it %.2f / %.2f / %.2f / %.2f, from it %.2f / %.2f / %.2f / %.2f\n",
                rows[i].name.c_str(), rows[i].points, to.p50, to.p95, to.p99, to.max, from.p50, from.p95,
                from.p99, from.max);
  }
  if (summary.truth) {
    std::printf("final clouds against the truth (gt_cloud.ply): coverage within 2 mm, p95 to it [mm]:");
    for (const IntegratorRow& r : rows) {
      std::printf("%s %s %.3f, %.2f", &r == &rows[0] ? "" : ";", r.name.c_str(), r.truth_coverage_2mm,
                  r.truth_p95_mm);
    }
    std::printf("\n");
  }
  if (summary.two_threads) {
    std::printf("each integrator's final cloud at 2 threads: %s\n",
                summary.same_clouds_at_both_thread_counts ? "the same as at 1" : "NOT the same as at 1");
  }
}

nlohmann::ordered_json IntegratorJson(const IntegratorSummary& summary) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (size_t i = 0; i < summary.rows.size(); ++i) {
    const IntegratorRow& r = summary.rows[i];
    nlohmann::ordered_json row = {{"name", r.name}, {"frames", r.frames}};
    for (int k = 0; k < (summary.two_threads ? 2 : 1); ++k) {
      row[k == 0 ? "threads_1" : "threads_2"] = {
          {"integrate_ms", r.integrate_ms[k]},
          {"extract_ms", {{"p50", r.extract_p50_ms[k]}, {"p99", r.extract_p99_ms[k]}}}};
    }
    row["integrate_over_product"] = r.integrate_over_product;
    row["points"] = r.points;
    if (i > 0) {
      row["to_product_mm"] = Json(r.to_product);
      row["from_product_mm"] = Json(r.from_product);
    }
    if (summary.truth) {
      row["truth_coverage_2mm"] = r.truth_coverage_2mm;
      row["truth_p95_mm"] = r.truth_p95_mm;
    }
    rows.push_back(row);
  }
  nlohmann::ordered_json j = {{"extract_every_frames", IntegratorComparison::kExtractEvery},
                              {"integrators", rows}};
  if (summary.two_threads) j["same_clouds_at_1_and_2_threads"] = summary.same_clouds_at_both_thread_counts;
  return j;
}

}  // namespace graspfill::cli
