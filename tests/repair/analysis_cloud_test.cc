// SPDX-License-Identifier: BSD-3-Clause
#include "analysis_cloud.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <tuple>
#include <vector>

#include "cpu_time.hpp"
#include "synth/paper_protocol.hpp"

namespace graspfill::repair {
namespace {

using testing::BestOf3CpuMs;

PointList ProtocolCloud(int num_points) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = num_points;
  return synth::MakePaperProtocolCloud(config).holey;
}

// The own grouping against Open3D's VoxelDownSample on the same voxel grid
// (Open3D's starts half a voxel below the bounding box): the same number
// of voxels and the same centroids; the times printed side by side. (Not
// against VoxelDownSampleAndTrace: the Eigen::MatrixXi it returns is
// allocated with Open3D's build's alignment and freed with ours, which
// AddressSanitizer reports as a heap overflow.)
TEST(AnalysisCloud, SameVoxelsAsOpen3dAndTiming) {
  const PointList points = ProtocolCloud(61000);  // ~50k after the cut
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const double voxel = 0.0018;
  const Eigen::Vector3f origin = box.min() - Eigen::Vector3f::Constant(0.5f * voxel);
  std::vector<VoxelMember> members(points.size());
  size_t own_voxels = 0;
  const double own_ms = BestOf3CpuMs([&] { own_voxels = GroupByVoxel(points, origin, voxel, &members); });

  open3d::geometry::PointCloud cloud;
  for (const Eigen::Vector3f& p : points) cloud.points_.push_back(p.cast<double>());
  std::shared_ptr<open3d::geometry::PointCloud> reduced;
  const double o3d_ms = BestOf3CpuMs([&] { reduced = cloud.VoxelDownSample(voxel); });
  std::printf(
      "voxel grouping of %zu points at %.1f mm: own %.1f ms, Open3D %.1f ms; "
      "%zu vs %zu voxels\n",
      points.size(), 1e3 * voxel, own_ms, o3d_ms, own_voxels, reduced->points_.size());
  EXPECT_EQ(own_voxels, reduced->points_.size());
  // Own centroids, then each matched to Open3D's (exact up to rounding;
  // a point on a voxel face may fall either way in float vs double).
  std::vector<Eigen::Vector3d> own;
  for (size_t start = 0; start < members.size();) {
    size_t end = start;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < members.size() && members[end].key == members[start].key) {
      sum += points[static_cast<size_t>(members[end++].index)].cast<double>();
    }
    own.push_back(sum / static_cast<double>(end - start));
    start = end;
  }
  auto lexicographic = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  };
  std::vector<Eigen::Vector3d> theirs = reduced->points_;
  std::sort(own.begin(), own.end(), lexicographic);
  std::sort(theirs.begin(), theirs.end(), lexicographic);
  size_t differ = 0;
  for (size_t i = 0; i < std::min(own.size(), theirs.size()); ++i) {
    differ += (own[i] - theirs[i]).norm() > 1e-6;
  }
  EXPECT_LT(differ, own.size() / 100) << differ << " of " << own.size() << " centroids differ";
}

TEST(AnalysisCloud, ReducesToAboutTheTargetAndMapsEveryPoint) {
  const PointList points = ProtocolCloud(61000);
  const NeighborIndex index(points);
  const AnalysisCloud a = MakeAnalysisCloud(index, AnalysisConfig{});
  ASSERT_TRUE(a.reduced());
  std::printf("%zu points -> %zu centroids at %.2f mm\n", points.size(), a.points.size(), 1e3 * a.voxel_m);
  EXPECT_GT(a.points.size(), 0.5 * AnalysisConfig{}.target_points);
  EXPECT_LT(a.points.size(), 1.5 * AnalysisConfig{}.target_points);
  ASSERT_EQ(a.voxel_of.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const int v = a.voxel_of[i];
    ASSERT_GE(v, 0);
    ASSERT_LT(v, static_cast<int>(a.points.size()));
    // A centroid lies within its voxel's diagonal of each member.
    EXPECT_LT((a.points[static_cast<size_t>(v)] - points[i]).norm(), 1.7321 * a.voxel_m + 1e-6);
  }
  // Deterministic.
  const AnalysisCloud b = MakeAnalysisCloud(index, AnalysisConfig{});
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.voxel_of, b.voxel_of);
}

TEST(AnalysisCloud, SmallCloudsAndTheOffSwitchKeepTheInput) {
  const PointList points = ProtocolCloud(5000);
  const NeighborIndex index(points);
  EXPECT_FALSE(MakeAnalysisCloud(index, AnalysisConfig{}).reduced());
  AnalysisConfig off;
  off.target_points = 0;
  const PointList fused_size = ProtocolCloud(28000);  // ~23k: a fused cloud's size
  const NeighborIndex fused_index(fused_size);
  EXPECT_FALSE(MakeAnalysisCloud(fused_index, AnalysisConfig{}).reduced());
  const PointList big = ProtocolCloud(40000);
  const NeighborIndex big_index(big);
  EXPECT_FALSE(MakeAnalysisCloud(big_index, off).reduced());
  AnalysisConfig bad;
  bad.target_points = -1;
  EXPECT_THROW(MakeAnalysisCloud(index, bad), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::repair
