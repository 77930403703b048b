// SPDX-License-Identifier: BSD-3-Clause
// Cloud-to-cloud quality metrics: compares a predicted (repaired) object cloud
// with a hole-free ground truth. The headline number is the chamfer distance
// of the paper (Eq. 6); F-scores and percentiles say *where* the error is.
//
// Units: inputs are in meters (like every graspfill cloud); the metrics are
// reported in millimeters (distances) or square millimeters (chamfer), which
// keeps the numbers of a hand-sized object readable. The nearest distances
// come from mesh/nearest_distances.hpp, the percentiles from
// core/percentile.hpp.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace graspfill::eval {

/// Result of Compare(). "Within tau" means a nearest-neighbour distance
/// d <= tau.
struct CloudMetrics {
  /// Paper Eq. 6: mean squared NN distance pred->gt plus gt->pred [mm^2].
  double chamfer_mm2{0.0};
  /// First term of Eq. 6: mean over pred of the squared distance to gt [mm^2].
  double pred_to_gt_mean_sq_mm2{0.0};
  /// Second term of Eq. 6: mean over gt of the squared distance to pred [mm^2].
  double gt_to_pred_mean_sq_mm2{0.0};
  /// F-score at tau = 1 mm: 2PR/(P+R), P = fraction of pred within tau of gt
  /// (precision), R = fraction of gt within tau of pred (recall); 0 when
  /// P + R = 0. In [0, 1].
  double fscore_1mm{0.0};
  /// F-score at tau = 2 mm (same definition as fscore_1mm).
  double fscore_2mm{0.0};
  /// Recall at 2 mm: the share of gt within 2 mm of pred (the issues'
  /// "coverage" of the true surface). In [0, 1].
  double coverage_2mm{0.0};
  /// Precision at 2 mm: the share of pred within 2 mm of gt. In [0, 1].
  double precision_2mm{0.0};
  /// 95th percentile of the pred->gt NN distances [mm] (linear
  /// interpolation between order statistics, as numpy's default).
  double p95_pred_to_gt_mm{0.0};
  /// 95th percentile of the gt->pred NN distances [mm]; large values mean
  /// unrepaired holes.
  double p95_gt_to_pred_mm{0.0};
  /// Largest pred->gt NN distance [mm]: the worst outlier in the prediction.
  double max_pred_to_gt_mm{0.0};
  size_t num_pred{0};  ///< number of predicted points
  size_t num_gt{0};    ///< number of ground-truth points
};

/// Fraction of `distances_m` that are <= `tau_m` (0 for an empty vector).
double FractionWithin(const std::vector<double>& distances_m, double tau_m);

/// Compares a predicted cloud with the ground truth, both in meters and in
/// the same frame. Deterministic: same inputs, same bits out.
/// @throws std::invalid_argument if either cloud is empty or holds a
///         non-finite coordinate (the message names the cloud and the index).
CloudMetrics Compare(const std::vector<Eigen::Vector3f>& pred, const std::vector<Eigen::Vector3f>& gt);

}  // namespace graspfill::eval
