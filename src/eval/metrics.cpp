// SPDX-License-Identifier: BSD-3-Clause
// Chamfer distance (paper Eq. 6), F-scores and percentiles between two
// clouds. Nearest neighbours come from mesh::NearestSquaredDistances
// (Open3D's KD-tree).
#include "eval/metrics.hpp"

#include <algorithm>
#include <cmath>

#include "graspfill/core/percentile.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill::eval {
namespace {

constexpr double kMetersToMm = 1e3;
constexpr double kSqMetersToSqMm = 1e6;

std::vector<double> Sqrt(std::vector<double> v) {
  for (double& x : v) x = std::sqrt(x);
  return v;
}

// Summed in index order so the result is bit-reproducible.
double Mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

double FScore(const std::vector<double>& pred_to_gt_m, const std::vector<double>& gt_to_pred_m,
              double tau_m) {
  const double precision = FractionWithin(pred_to_gt_m, tau_m);
  const double recall = FractionWithin(gt_to_pred_m, tau_m);
  if (precision + recall <= 0.0) return 0.0;
  return 2.0 * precision * recall / (precision + recall);
}

}  // namespace

double FractionWithin(const std::vector<double>& distances_m, double tau_m) {
  if (distances_m.empty()) return 0.0;
  const auto within =
      std::count_if(distances_m.begin(), distances_m.end(), [tau_m](double d) { return d <= tau_m; });
  return static_cast<double>(within) / static_cast<double>(distances_m.size());
}

CloudMetrics Compare(const std::vector<Eigen::Vector3f>& pred, const std::vector<Eigen::Vector3f>& gt) {
  mesh::CheckCloud(pred, "predicted");
  mesh::CheckCloud(gt, "ground-truth");
  // Squared distances feed Eq. 6 directly: no sqrt and square round trip
  // blurs an exact geometry.
  const std::vector<double> pred_to_gt_sq = mesh::NearestSquaredDistances(pred, gt);
  const std::vector<double> gt_to_pred_sq = mesh::NearestSquaredDistances(gt, pred);
  const std::vector<double> pred_to_gt = Sqrt(pred_to_gt_sq);
  const std::vector<double> gt_to_pred = Sqrt(gt_to_pred_sq);

  CloudMetrics m;
  m.num_pred = pred.size();
  m.num_gt = gt.size();
  m.pred_to_gt_mean_sq_mm2 = Mean(pred_to_gt_sq) * kSqMetersToSqMm;
  m.gt_to_pred_mean_sq_mm2 = Mean(gt_to_pred_sq) * kSqMetersToSqMm;
  m.chamfer_mm2 = m.pred_to_gt_mean_sq_mm2 + m.gt_to_pred_mean_sq_mm2;
  m.fscore_1mm = FScore(pred_to_gt, gt_to_pred, 1.0 / kMetersToMm);
  m.fscore_2mm = FScore(pred_to_gt, gt_to_pred, 2.0 / kMetersToMm);
  m.coverage_2mm = FractionWithin(gt_to_pred, 2.0 / kMetersToMm);
  m.precision_2mm = FractionWithin(pred_to_gt, 2.0 / kMetersToMm);
  m.p95_pred_to_gt_mm = Percentile(pred_to_gt, 95.0) * kMetersToMm;
  m.p95_gt_to_pred_mm = Percentile(gt_to_pred, 95.0) * kMetersToMm;
  m.max_pred_to_gt_mm = *std::max_element(pred_to_gt.begin(), pred_to_gt.end()) * kMetersToMm;
  return m;
}

}  // namespace graspfill::eval
