// SPDX-License-Identifier: BSD-3-Clause
// Chamfer distance (paper Eq. 6), F-scores and percentiles between two
// clouds. Nearest neighbours come from Open3D's KD-tree (nanoflann inside).
#include "graspfill/eval/metrics.hpp"

#include <open3d/geometry/KDTreeFlann.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace graspfill::eval {
namespace {

constexpr double kMetersToMm = 1e3;
constexpr double kSqMetersToSqMm = 1e6;

// Rejects what would silently poison the metrics: an empty cloud makes every
// mean undefined, and a NaN would make the KD-tree answer garbage.
void Validate(const std::vector<Eigen::Vector3f>& cloud,
              const std::string& name) {
  if (cloud.empty()) {
    throw std::invalid_argument("graspfill::eval: the " + name +
                                " cloud is empty");
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud[i].allFinite()) {
      std::ostringstream msg;
      msg << "graspfill::eval: the " << name << " cloud has a non-finite "
          << "coordinate at point " << i << " (" << cloud[i].x() << ", "
          << cloud[i].y() << ", " << cloud[i].z() << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

// Squared NN distances [m^2] from each point of `from` to `to`; inputs are
// already validated. Squared values feed Eq. 6 directly, so no sqrt/square
// round trip blurs an exact geometry.
std::vector<double> NearestSquaredDistances(
    const std::vector<Eigen::Vector3f>& from,
    const std::vector<Eigen::Vector3f>& to) {
  Eigen::MatrixXd data(3, static_cast<Eigen::Index>(to.size()));
  for (size_t i = 0; i < to.size(); ++i) {
    data.col(static_cast<Eigen::Index>(i)) = to[i].cast<double>();
  }
  open3d::geometry::KDTreeFlann tree;
  if (!tree.SetMatrixData(data)) {
    throw std::runtime_error("graspfill::eval: building the KD-tree failed");
  }
  std::vector<double> d2(from.size());
  std::vector<int> index(1);
  std::vector<double> dist2(1);
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d query = from[i].cast<double>();
    if (tree.SearchKNN(query, 1, index, dist2) < 1) {
      throw std::runtime_error("graspfill::eval: KD-tree search found nothing");
    }
    d2[i] = dist2[0];
  }
  return d2;
}

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

double FScore(const std::vector<double>& pred_to_gt_m,
              const std::vector<double>& gt_to_pred_m, double tau_m) {
  const double precision = FractionWithin(pred_to_gt_m, tau_m);
  const double recall = FractionWithin(gt_to_pred_m, tau_m);
  if (precision + recall <= 0.0) return 0.0;
  return 2.0 * precision * recall / (precision + recall);
}

}  // namespace

std::vector<double> NearestDistances(const std::vector<Eigen::Vector3f>& from,
                                     const std::vector<Eigen::Vector3f>& to) {
  Validate(from, "'from'");
  Validate(to, "'to'");
  return Sqrt(NearestSquaredDistances(from, to));
}

double FractionWithin(const std::vector<double>& distances_m, double tau_m) {
  if (distances_m.empty()) return 0.0;
  const auto within =
      std::count_if(distances_m.begin(), distances_m.end(),
                    [tau_m](double d) { return d <= tau_m; });
  return static_cast<double>(within) / static_cast<double>(distances_m.size());
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) {
    throw std::invalid_argument("graspfill::eval: percentile of no values");
  }
  if (!(q >= 0.0 && q <= 100.0)) {
    throw std::invalid_argument(
        "graspfill::eval: percentile must be in [0, 100], got " +
        std::to_string(q));
  }
  std::sort(values.begin(), values.end());
  const double rank = q / 100.0 * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(rank));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  const double frac = rank - static_cast<double>(lo);
  return values[lo] + frac * (values[hi] - values[lo]);
}

CloudMetrics Compare(const std::vector<Eigen::Vector3f>& pred,
                     const std::vector<Eigen::Vector3f>& gt) {
  Validate(pred, "predicted");
  Validate(gt, "ground-truth");

  const std::vector<double> pred_to_gt_sq = NearestSquaredDistances(pred, gt);
  const std::vector<double> gt_to_pred_sq = NearestSquaredDistances(gt, pred);
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
  m.max_pred_to_gt_mm =
      *std::max_element(pred_to_gt.begin(), pred_to_gt.end()) * kMetersToMm;
  return m;
}

}  // namespace graspfill::eval
