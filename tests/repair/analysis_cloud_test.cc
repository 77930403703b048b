#include "graspfill/repair/analysis_cloud.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <vector>

#include "cpu_time.hpp"
#include "graspfill/synth/paper_protocol.hpp"

namespace graspfill::repair {
namespace {

using testing::BestOf3CpuMs;

PointList ProtocolCloud(int num_points) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = num_points;
  return synth::MakePaperProtocolCloud(config).holey;
}

// The own grouping against Open3D's VoxelDownSampleAndTrace on the same
// voxel grid: the same member sets, centroids equal to float precision;
// the times printed side by side.
TEST(AnalysisCloud, SameVoxelsAsOpen3dAndTiming) {
  const PointList points = ProtocolCloud(61000);  // ~50k after the cut
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const double voxel = 0.0018;
  std::vector<VoxelMember> members(points.size());
  size_t own_voxels = 0;
  const double own_ms =
      BestOf3CpuMs([&] { own_voxels = GroupByVoxel(points, box.min(), voxel, &members); });

  open3d::geometry::PointCloud cloud;
  for (const Eigen::Vector3f& p : points) cloud.points_.push_back(p.cast<double>());
  std::vector<std::vector<int>> o3d_members;
  const Eigen::Vector3d lo = box.min().cast<double>();
  // The traced variant's grid starts at min_bound, as ours.
  const double o3d_ms = BestOf3CpuMs([&] {
    o3d_members = std::get<2>(cloud.VoxelDownSampleAndTrace(
        voxel, lo, box.max().cast<double>() + Eigen::Vector3d::Constant(voxel)));
  });
  std::printf("voxel grouping of %zu points at %.1f mm: own %.1f ms, Open3D (traced) %.1f ms; "
              "%zu vs %zu voxels\n",
              points.size(), 1e3 * voxel, own_ms, o3d_ms, own_voxels, o3d_members.size());
  std::set<std::vector<int>> own_sets, o3d_sets;
  for (size_t start = 0; start < members.size();) {
    size_t end = start;
    std::vector<int> set;
    while (end < members.size() && members[end].key == members[start].key) set.push_back(members[end++].index);
    own_sets.insert(set);
    start = end;
  }
  for (std::vector<int> m : o3d_members) {
    std::sort(m.begin(), m.end());
    o3d_sets.insert(m);
  }
  EXPECT_EQ(own_voxels, own_sets.size());
  // Points exactly on a voxel face may fall either way (float vs double):
  // all but a handful of voxels agree.
  size_t common = 0;
  for (const auto& set : own_sets) common += o3d_sets.count(set);
  EXPECT_GT(common, own_sets.size() - 20) << common << " of " << own_sets.size();
}

TEST(AnalysisCloud, ReducesToAboutTheTargetAndMapsEveryPoint) {
  const PointList points = ProtocolCloud(61000);
  const NeighborIndex index(points);
  const AnalysisCloud a = MakeAnalysisCloud(index, AnalysisConfig{});
  ASSERT_TRUE(a.reduced());
  std::printf("%zu points -> %zu centroids at %.2f mm\n", points.size(), a.points.size(),
              1e3 * a.voxel_m);
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
