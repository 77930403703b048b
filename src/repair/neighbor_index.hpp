// SPDX-License-Identifier: BSD-3-Clause
// k-nearest-neighbour queries over one cloud, built once and shared by the
// repair steps (normals, outliers, boundary detection, linking, densities),
// so that no step builds its own tree.
//
// A uniform grid (cells ~1.25x the typical 20th-neighbour distance, points
// counting-sorted by cell), exact: a query grows its block of cells until
// nothing outside can be nearer. Measured against Open3D's KDTreeFlann (the
// previous implementation) by neighbor_index_test.cc
// (MatchesKdTreeFlannOn50kAndTiming), 54k-point protocol cylinder, one
// core, CPU time, on the shared 2-core VM: kNN(21) per point 164 ms vs
// 193 ms, build 7 ms vs 28 ms, and AllKnn(21) (the table the outlier
// filter and the boundary detection share) 130 ms; identical distances.
// Ties are broken by index, so every answer is deterministic.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// The k nearest neighbours of every point of a cloud, row by row.
struct KnnTable {
  int k{0};
  std::vector<int> indices;               ///< size() * k; row i: point i's,
  std::vector<double> squared_distances;  ///< nearest first (itself first)
  size_t size() const { return k > 0 ? indices.size() / static_cast<size_t>(k) : 0; }
  const int* Row(size_t i) const { return indices.data() + i * static_cast<size_t>(k); }
  const double* RowDistances(size_t i) const { return squared_distances.data() + i * static_cast<size_t>(k); }
};

class NeighborIndex {
 public:
  /// Builds the tree over `points` (kept by reference: they must outlive
  /// the index and stay unchanged). Throws std::invalid_argument if empty.
  explicit NeighborIndex(const PointList& points);
  ~NeighborIndex();
  NeighborIndex(const NeighborIndex&) = delete;
  NeighborIndex& operator=(const NeighborIndex&) = delete;

  /// The k nearest points of `query` (itself included when it is a cloud
  /// point), nearest first; squared distances [m^2] optional.
  void Knn(const Eigen::Vector3f& query, int k, std::vector<int>* indices,
           std::vector<double>* squared_distances = nullptr) const;
  /// All points within `radius_m` of `query`.
  void Radius(const Eigen::Vector3f& query, double radius_m, std::vector<int>* indices,
              std::vector<double>* squared_distances = nullptr) const;

  /// Whether some point lies within `radius_m` of `query` (the search stops
  /// at the first): Radius's answer, not empty, without collecting it.
  bool AnyWithin(const Eigen::Vector3f& query, double radius_m) const;
  /// The same, counting only the points `accept` takes: Radius's answer
  /// filtered by `accept`, not empty, without collecting or sorting it.
  bool AnyWithin(const Eigen::Vector3f& query, double radius_m,
                 const std::function<bool(const Eigen::Vector3f&)>& accept) const;

  /// Knn(p, k) for every cloud point p at once (k capped at the cloud's
  /// size): the points of one grid cell share their candidates, several
  /// times faster than one query per point. Same answers as Knn.
  KnnTable AllKnn(int k) const;
  /// The same for the points `queries` only (indices into the cloud,
  /// distinct; row r is queries[r]'s): the batch's speed for a subset.
  /// Throws std::invalid_argument on an index out of range or repeated.
  KnnTable KnnOf(const std::vector<int>& queries, int k) const;

  const PointList& points() const { return points_; }
  size_t size() const { return points_.size(); }

 private:
  // AllKnn (row_of null) and KnnOf: row_of[point] its row, or -1.
  KnnTable Table(int k, const std::vector<int>* row_of) const;
  // Both AnyWithins (defined and instantiated in the source only).
  template <typename Accept>
  bool AnyWithinIf(const Eigen::Vector3f& query, double radius_m, const Accept& accept) const;

  const PointList& points_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `table` (over some cloud) restricted to the points `kept` (increasing
/// indices into that cloud), over `kept_index` built on exactly those
/// points: rows renumbered, removed neighbours skipped, and a row that
/// lost any queried afresh. Cheap when few points were removed.
KnnTable RestrictTable(const KnnTable& table, const std::vector<int>& kept, const NeighborIndex& kept_index);

/// Mean distance of about `samples` points (evenly strided) to their
/// nearest other point: the cloud's spacing [m]; 0 when none has one.
double MeanNearestDistance(const NeighborIndex& index, int samples);

/// The box around the bulk of `points`: per axis the 0.1% and 99.9%
/// quantiles widened by half their distance on each side, cut to the
/// bounding box. A clean cloud's box is its bounding box; a few stray points
/// far away are outside it (the index searches them apart, the repair's
/// limits measure this box). Non-finite points are ignored.
/// `max_samples` > 0 takes the quantiles of an even stride of about that
/// many points instead (the index's grid: any box that holds the bulk gives
/// the same answers, and the selection over every point cost 3% of a
/// repair).
Eigen::AlignedBox3f RobustBox(const PointList& points, size_t max_samples = 0);

}  // namespace graspfill::repair
