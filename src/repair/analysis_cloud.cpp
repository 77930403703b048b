// SPDX-License-Identifier: BSD-3-Clause
#include "analysis_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace graspfill::repair {

void AnalysisConfig::Validate() const {
  if (target_points < 0) throw std::invalid_argument("AnalysisConfig.target_points must be >= 0");
  if (spacing_samples < 8) throw std::invalid_argument("AnalysisConfig.spacing_samples must be >= 8");
  if (reduce_above_points < 0) {
    throw std::invalid_argument("AnalysisConfig.reduce_above_points must be >= 0");
  }
}

size_t GroupByVoxel(const PointList& points, const Eigen::Vector3f& origin, double voxel_m,
                    std::vector<VoxelMember>* members) {
  // 21 bits per axis: 2 million voxels a side, far beyond any object.
  const auto cell = [&](float x, float o) {
    return static_cast<uint64_t>(std::clamp(std::floor((x - o) / voxel_m), 0.0, 2097151.0));
  };
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    (*members)[i] = {
        (cell(p.z(), origin.z()) << 42) | (cell(p.y(), origin.y()) << 21) | cell(p.x(), origin.x()),
        static_cast<int>(i)};
  }
  std::sort(members->begin(), members->end(), [](const VoxelMember& a, const VoxelMember& b) {
    return a.key < b.key || (a.key == b.key && a.index < b.index);
  });
  size_t voxels = 0;
  for (size_t i = 0; i < members->size(); ++i) {
    voxels += i == 0 || (*members)[i].key != (*members)[i - 1].key;
  }
  return voxels;
}

AnalysisCloud MakeAnalysisCloud(const NeighborIndex& input, const AnalysisConfig& config) {
  config.Validate();
  AnalysisCloud out;
  const PointList& points = input.points();
  const size_t n = points.size();
  if (config.target_points == 0 || n <= static_cast<size_t>(config.target_points) ||
      n <= static_cast<size_t>(config.reduce_above_points)) {
    return out;
  }

  // The surface area per input point, from the distance to the 8th
  // neighbour on a strided sample (a disc of radius r8 holds ~8 points on
  // a random sample and on a grid alike).
  constexpr int kK = 8;
  std::vector<int> nn;
  std::vector<double> d2;
  double area_sum = 0.0;
  int count = 0;
  const size_t stride = std::max<size_t>(1, n / static_cast<size_t>(config.spacing_samples));
  for (size_t i = 0; i < n; i += stride) {
    input.Knn(points[i], kK + 1, &nn, &d2);
    if (d2.size() == kK + 1 && d2[kK] > 0.0) area_sum += M_PI * d2[kK] / kK, ++count;
  }
  if (count == 0) return out;  // all points coincide: nothing to reduce
  const double area_per_point = area_sum / count;

  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  // A surface crosses ~1.5 / v^2 voxels of side v per unit area (averaged
  // over orientations), so a voxel holds ~v^2 / (1.5 a) points: v for
  // about target_points centroids. Coarser once if far off.
  double voxel = std::sqrt(1.5 * area_per_point * static_cast<double>(n) / config.target_points);
  std::vector<VoxelMember> members(n);
  for (int attempt = 0;; ++attempt) {
    const size_t voxels = GroupByVoxel(points, box.min(), voxel, &members);
    const double ratio = static_cast<double>(voxels) / config.target_points;
    if (ratio > 1.5 && attempt == 0) {
      voxel *= std::sqrt(ratio);
      continue;
    }
    out.voxel_m = voxel;
    out.points.reserve(voxels);
    out.voxel_of.assign(n, -1);
    for (size_t start = 0; start < n;) {
      size_t end = start;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      while (end < n && members[end].key == members[start].key) {
        sum += points[static_cast<size_t>(members[end].index)].cast<double>();
        out.voxel_of[static_cast<size_t>(members[end].index)] = static_cast<int>(out.points.size());
        ++end;
      }
      out.points.push_back((sum / static_cast<double>(end - start)).cast<float>());
      start = end;
    }
    break;
  }
  return out;
}

}  // namespace graspfill::repair
