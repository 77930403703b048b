// SPDX-License-Identifier: BSD-3-Clause
// Step 1 of the hole repair (Cui et al. 2021, section 2.2.1): statistical
// outlier removal with the semantics of PCL's StatisticalOutlierRemoval.
//
// For every point, d = mean distance to its `nb_neighbors` nearest other
// points; a point is kept when d <= mean(d) + std_ratio * stddev(d), the
// statistics taken over the whole cloud (sample standard deviation), or
// when d <= min_median_ratio * median(d) (see the config).
//
// Implementation choice, measured by outlier_removal_test.cc
// (MatchesOpen3dAndTiming) on a 50.1k-point paper-protocol cylinder plus
// 200 far points, Release, one core (OMP_THREAD_LIMIT=1), CPU time, best of
// 3, on a shared 2-core VM (ranges over 4 sessions; load made them vary):
//   - own code over NeighborIndex (one float->double tree, buffers reused):
//     170-275 ms, of which the tree build 24-31 ms;
//   - Open3D PointCloud::RemoveStatisticalOutliers(nb_neighbors + 1, ...):
//     185-270 ms (copy to Vector3d, its own tree), no faster on its two
//     OpenMP threads on the loaded VM.
// Both spend nearly all of it in the kNN queries. Same decisions (0 of
// 50.1k differ): Open3D counts the point itself, which scales every mean by
// k / (k + 1) and so leaves the test unchanged. The own version is kept:
// single-threaded by design, no double copy of the cloud, and through the
// NeighborIndex overload a caller that already has a tree over the raw
// cloud skips building a second one.
#pragma once

#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

/// Parameters of the statistical outlier filter (PCL's names: MeanK,
/// StddevMulThresh).
struct OutlierConfig {
  /// Neighbours (the point itself excluded) whose mean distance is the
  /// point's statistic. PCL's tutorial and Open3D's examples use 20.
  int nb_neighbors{20};
  /// Threshold in standard deviations above the cloud's mean of the means.
  /// 2.0 (PCL's tutorial, Open3D's examples) removes points a couple of cm
  /// off a surface sampled at ~1 mm and keeps > 99% of the surface (all of
  /// it in the tests).
  double std_ratio{2.0};
  /// ... and above this many times the median of the means (graspfill's
  /// addition; 0 = PCL's test alone). On a clean 50k-point random sample of
  /// the protocol's cylinder the test alone drops 2.9% of the surface (the
  /// points in sparse spots) and the false holes this opens broke the
  /// boundary lines; the largest mean there is ~1.6x the median, while an
  /// outlier a few mm off the surface is many times it.
  double min_median_ratio{2.0};

  /// Throws std::invalid_argument unless nb_neighbors >= 1, std_ratio is
  /// finite and > 0 and min_median_ratio finite and >= 0.
  void Validate() const;
};

/// Indices of the points of `points` that pass the filter, in increasing
/// order. Non-finite points (NaN, inf) are never kept and take no part in
/// the statistics. A cloud with no more than `nb_neighbors` finite points
/// has too few neighbours for the statistic and is returned whole (its
/// finite points). Builds one NeighborIndex over the finite points.
/// Throws std::invalid_argument on an invalid config.
std::vector<int> RemoveOutliers(const PointList& points, const OutlierConfig& config);

/// Same, over an index the caller already built (its points must all be
/// finite). Indices refer to index.points().
std::vector<int> RemoveOutliers(const NeighborIndex& index, const OutlierConfig& config);

/// Same, from the cloud's kNN table (NeighborIndex::AllKnn with at least
/// nb_neighbors + 1 columns, e.g. shared with the boundary detection).
/// Throws std::invalid_argument on a table with too few columns.
std::vector<int> RemoveOutliers(const KnnTable& table, const OutlierConfig& config);

}  // namespace graspfill::repair
