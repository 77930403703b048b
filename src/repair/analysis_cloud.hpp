// SPDX-License-Identifier: BSD-3-Clause
// graspfill's best mode looks for the holes on a coarser copy of the cloud
// (not in the paper): the voxel centroids of the input, about
// `target_points` of them. Holes are centimetres across (claw holes
// 25 x 45 mm, the top) while a fused or protocol cloud samples the surface
// every ~1 mm, so steps 1-6 (outliers, boundary points and lines, the
// frame, classification, completion) lose nothing at ~2 mm and cost a
// third; steps 7-8 (the fills) still read every input point. The centroids
// also sample the surface more evenly than a random sample, which leaves
// fewer chance gaps for the boundary detector.
//
// The grouping is own code, a sort by voxel key, because the repair needs
// each centroid's members: Open3D's VoxelDownSample gives the same
// centroids (analysis_cloud_test.cc, SameVoxelsAsOpen3dAndTiming: 11,682
// voxels of 50k points at 1.8 mm, own 4.1 ms, Open3D 5.0 ms) but not the
// members, and its VoxelDownSampleAndTrace, which does, took 13-23 ms and
// returns an Eigen::MatrixXi allocated with Open3D's build's alignment and
// freed with ours (AddressSanitizer: heap overflow). The order is a fixed
// (z, y, x), not a hash map's.
// Pure, single-threaded, deterministic.
#pragma once

#include <cstdint>
#include <vector>

#include "graspfill/repair/repair_types.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {

struct AnalysisConfig {
  /// Clouds with more points than `reduce_above_points` are reduced to
  /// about `target_points` (within ~50%); 0 = never (the paper's method
  /// works on the input). 8000 keeps every protocol row at the floor
  /// (bench repair) in ~80 ms for 50k input points; 12000 cost ~30 ms
  /// more for no gain.
  int target_points{8000};
  /// A fused cloud (1.5 mm TSDF voxels, 10-25k points) stays whole: its
  /// claw holes can be slits a few voxels wide that a 2.5x coarser copy
  /// closes (the replayed prism lost all three).
  int reduce_above_points{25000};
  /// Points sampled to measure the input's spacing.
  int spacing_samples{256};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

struct AnalysisCloud {
  PointList points;           ///< the voxel centroids, or empty: use the input
  std::vector<int> voxel_of;  ///< per input point, its centroid (empty: identity)
  double voxel_m{0.0};        ///< 0 when the input is used as it is
  bool reduced() const { return voxel_m > 0.0; }
};

/// One input point's voxel: key = z << 42 | y << 21 | x (cell indices
/// from `origin`), and the point's index.
struct VoxelMember {
  uint64_t key;
  int index;
};

/// Fills `members` (sized like `points`) sorted by (key, index); returns
/// the number of distinct voxels. Points must lie at or above `origin`.
size_t GroupByVoxel(const PointList& points, const Eigen::Vector3f& origin, double voxel_m,
                    std::vector<VoxelMember>* members);

/// The analysis cloud of `input.points()` (finite points).
/// @throws std::invalid_argument on a bad config.
AnalysisCloud MakeAnalysisCloud(const NeighborIndex& input, const AnalysisConfig& config);

}  // namespace graspfill::repair
