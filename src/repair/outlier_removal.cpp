// SPDX-License-Identifier: BSD-3-Clause
#include "outlier_removal.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace graspfill::repair {

void OutlierConfig::Validate() const {
  if (nb_neighbors < 1) {
    throw std::invalid_argument("OutlierConfig: nb_neighbors must be >= 1, got " +
                                std::to_string(nb_neighbors));
  }
  if (!std::isfinite(std_ratio) || std_ratio <= 0.0) {
    throw std::invalid_argument("OutlierConfig: std_ratio must be finite and > 0, got " +
                                std::to_string(std_ratio));
  }
  if (!std::isfinite(min_median_ratio) || min_median_ratio < 0.0) {
    throw std::invalid_argument("OutlierConfig: min_median_ratio must be finite and >= 0, got " +
                                std::to_string(min_median_ratio));
  }
}

std::vector<int> RemoveOutliers(const NeighborIndex& index, const OutlierConfig& config) {
  config.Validate();
  return RemoveOutliers(index.AllKnn(config.nb_neighbors + 1), config);
}

std::vector<int> RemoveOutliers(const KnnTable& table, const OutlierConfig& config) {
  config.Validate();
  const int n = static_cast<int>(table.size());
  std::vector<int> kept;
  if (n <= config.nb_neighbors) {
    // Fewer points than the statistic needs: nothing can be judged.
    kept.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) kept[static_cast<size_t>(i)] = i;
    return kept;
  }
  if (table.k < config.nb_neighbors + 1) {
    throw std::invalid_argument(
        "RemoveOutliers: the kNN table has " + std::to_string(table.k) +
        " columns, the filter needs nb_neighbors + 1 = " + std::to_string(config.nb_neighbors + 1));
  }

  // Mean distance to the k nearest other points (PCL: k + 1 nearest and
  // skip the point itself, which comes first at distance 0; with duplicate
  // points some point at distance 0 does).
  const int k = config.nb_neighbors;
  std::vector<double> mean_distance(static_cast<size_t>(n));
  double sum = 0.0;
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double* d2 = table.RowDistances(static_cast<size_t>(i));
    double s = 0.0;
    for (int j = 1; j <= k; ++j) s += std::sqrt(d2[j]);
    const double mean = s / k;
    mean_distance[static_cast<size_t>(i)] = mean;
    sum += mean;
    sum_sq += mean * mean;
  }
  const double count = static_cast<double>(n);
  const double cloud_mean = sum / count;
  // Sample variance, as PCL (Bessel's correction); clamp the rounding.
  const double variance = std::max(0.0, (sum_sq - sum * sum / count) / (count - 1.0));
  // The median floor: on a clean random sample the plain test drops the
  // ~3% of surface points that happen to sit in sparse spots, which opens
  // small false holes; an outlier is also far from the typical spacing.
  std::vector<double> sorted = mean_distance;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double threshold = std::max(cloud_mean + config.std_ratio * std::sqrt(variance),
                                    config.min_median_ratio * sorted[static_cast<size_t>(n / 2)]);

  kept.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (mean_distance[static_cast<size_t>(i)] <= threshold) kept.push_back(i);
  }
  return kept;
}

std::vector<int> RemoveOutliers(const PointList& points, const OutlierConfig& config) {
  config.Validate();
  // Non-finite points would poison the tree and the statistics: filter them
  // first, copying only when there are any.
  std::vector<int> finite;
  finite.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].allFinite()) finite.push_back(static_cast<int>(i));
  }
  if (finite.empty()) return {};
  if (finite.size() == points.size()) {
    const NeighborIndex index(points);
    return RemoveOutliers(index, config);
  }
  PointList compact;
  compact.reserve(finite.size());
  for (const int i : finite) compact.push_back(points[static_cast<size_t>(i)]);
  const NeighborIndex index(compact);
  std::vector<int> kept = RemoveOutliers(index, config);
  for (int& i : kept) i = finite[static_cast<size_t>(i)];
  return kept;
}

}  // namespace graspfill::repair
