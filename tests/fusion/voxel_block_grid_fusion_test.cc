// SPDX-License-Identifier: BSD-3-Clause
// Open3D's tensor VoxelBlockGrid on the frames the pipeline fuses (the
// analytic sphere held by the claw, ../pipeline/sphere_scene.hpp) against
// the product's ScalableTSDFVolume on the same frames: what `graspfill
// bench` compares on the recording, here with the truth known.
#include "fusion/voxel_block_grid_fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "../pipeline/sphere_scene.hpp"
#include "graspfill/core/percentile.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill {
namespace {

using fusion::TsdfConfig;
using fusion::VoxelBlockGridConfig;
using fusion::VoxelBlockGridFusion;

// |distance to the sphere's centre - radius| of every point [m].
std::vector<double> SphereErrors(const ObjectCloud& cloud) {
  std::vector<double> e;
  for (const Eigen::Vector3f& p : cloud.points_G)
    e.push_back(std::abs((p.cast<double>() - kCentreG).norm() - kRadiusM));
  return e;
}

class VoxelBlockGridOnFusedFrames : public PipelineTest {
 protected:
  // Feeds the scene to a pipeline and every frame it fuses, as it fused
  // it, to each of `grids`; *legacy receives the pipeline's own cloud
  // (Open3D's ScalableTSDFVolume over the whole volume).
  void FuseBoth(const std::vector<VoxelBlockGridFusion*>& grids, ObjectCloud* legacy) {
    PipelineConfig config;
    Pipeline pipeline(config, Claw());
    int64_t seen = 0;
    Feed(&pipeline, 30, CameraIntrinsics{}, [&] {
      if (pipeline.stats().frames_integrated == seen) return;
      seen = pipeline.stats().frames_integrated;
      for (VoxelBlockGridFusion* grid : grids)
        grid->Integrate(pipeline.last_fused_frame(), pipeline.last_fused_T_C_V());
    });
    for (const VoxelBlockGridFusion* grid : grids) ASSERT_EQ(grid->frames_integrated(), seen);
    ASSERT_GE(seen, 25);
    pipeline.fusion().ExtractCloudUncached(legacy);
  }
};

// The same surface at the product's voxel (1.5 mm). The grids sample it at
// points half a voxel apart, so a point of one cloud is about a voxel's
// spacing from the other's nearest (p95 within a voxel; up to three at the
// rim of the seen region, where the two find their blocks and filter
// their crossings differently); what must agree is how far both lie from
// the sphere.
TEST_F(VoxelBlockGridOnFusedFrames, SameSurfaceAsScalableTsdfVolume) {
  for (const int block_resolution : {8, 16}) {
    SCOPED_TRACE(block_resolution);
    const TsdfConfig tsdf;
    VoxelBlockGridFusion grid(VoxelBlockGridConfig::Like(tsdf, block_resolution));
    ObjectCloud legacy, tensor;
    FuseBoth({&grid}, &legacy);
    grid.ExtractCloud(&tensor);
    ASSERT_GT(legacy.size(), 2000u);
    ASSERT_EQ(tensor.normals_G.size(), tensor.size());
    // As many zero crossings, give or take the rim of the seen region.
    EXPECT_NEAR(static_cast<double>(tensor.size()), static_cast<double>(legacy.size()), 0.1 * legacy.size());

    const double voxel_m = tsdf.voxel_m;
    const std::vector<double> to_legacy = mesh::NearestDistances(tensor.points_G, legacy.points_G);
    const std::vector<double> from_legacy = mesh::NearestDistances(legacy.points_G, tensor.points_G);
    EXPECT_LT(Percentile(to_legacy, 95), voxel_m);
    EXPECT_LT(Percentile(from_legacy, 95), voxel_m);
    EXPECT_LT(Percentile(to_legacy, 100), 3.0 * voxel_m);
    EXPECT_LT(Percentile(from_legacy, 100), 3.0 * voxel_m);

    const std::vector<double> tensor_err = SphereErrors(tensor), legacy_err = SphereErrors(legacy);
    EXPECT_LT(Percentile(tensor_err, 95), 0.5 * voxel_m);
    // No worse than the product's integrator by more than a tenth of a voxel.
    EXPECT_LT(Percentile(tensor_err, 95), Percentile(legacy_err, 95) + 0.1 * voxel_m);

    int outward = 0;
    for (size_t i = 0; i < tensor.size(); ++i) {
      const Eigen::Vector3d radial = (tensor.points_G[i].cast<double>() - kCentreG).normalized();
      outward += tensor.normals_G[i].cast<double>().dot(radial) > 0.9;
    }
    EXPECT_GT(outward, 0.95 * tensor.size());
  }
}

// The same frames give the same bytes, and a hash map sized too small
// grows instead of failing.
TEST_F(VoxelBlockGridOnFusedFrames, DeterministicAndGrowsPastItsBlockCount) {
  VoxelBlockGridConfig small = VoxelBlockGridConfig::Like(TsdfConfig{}, 16);
  small.block_count = 4;
  VoxelBlockGridFusion a(small), b(VoxelBlockGridConfig::Like(TsdfConfig{}, 16));
  ObjectCloud legacy, cloud_a, cloud_b;
  FuseBoth({&a, &b}, &legacy);
  EXPECT_GT(a.blocks(), small.block_count);
  EXPECT_EQ(a.blocks(), b.blocks());
  a.ExtractCloud(&cloud_a);
  b.ExtractCloud(&cloud_b);
  ASSERT_GT(cloud_a.size(), 0u);
  EXPECT_EQ(cloud_a.points_G, cloud_b.points_G);
  EXPECT_EQ(cloud_a.normals_G, cloud_b.normals_G);
}

// Why nearest_pixel: Open3D's own pixel lookup (the floor) reads depth half
// a pixel off, and the surface moves off the sphere by more than a tenth
// of a voxel at p95.
TEST_F(VoxelBlockGridOnFusedFrames, FloorPixelLookupIsOffTheSurface) {
  VoxelBlockGridConfig floor_config = VoxelBlockGridConfig::Like(TsdfConfig{}, 16);
  floor_config.nearest_pixel = false;
  VoxelBlockGridFusion nearest(VoxelBlockGridConfig::Like(TsdfConfig{}, 16)), floor(floor_config);
  ObjectCloud legacy, nearest_cloud, floor_cloud;
  FuseBoth({&nearest, &floor}, &legacy);
  nearest.ExtractCloud(&nearest_cloud);
  floor.ExtractCloud(&floor_cloud);
  ASSERT_GT(nearest_cloud.size(), 2000u);
  ASSERT_GT(floor_cloud.size(), 2000u);
  EXPECT_GT(Percentile(SphereErrors(floor_cloud), 95),
            Percentile(SphereErrors(nearest_cloud), 95) + 0.1 * TsdfConfig{}.voxel_m);
}

TEST(VoxelBlockGridFusion, EmptyFramesGiveAnEmptyCloud) {
  VoxelBlockGridFusion grid;
  DepthFrame empty;
  empty.depth_m.assign(static_cast<size_t>(empty.intrinsics.width) * empty.intrinsics.height, 0.0f);
  grid.Integrate(empty, T_C_G_at(0.0));
  EXPECT_EQ(grid.frames_integrated(), 1);
  EXPECT_EQ(grid.blocks(), 0);
  ObjectCloud cloud;
  cloud.points_G.emplace_back(1.0f, 2.0f, 3.0f);  // replaced
  grid.ExtractCloud(&cloud);
  EXPECT_EQ(cloud.size(), 0u);
}

TEST(VoxelBlockGridFusion, BadInputThrows) {
  VoxelBlockGridConfig bad;
  bad.sdf_trunc_m = bad.voxel_m;
  EXPECT_THROW(VoxelBlockGridFusion{bad}, std::invalid_argument);
  bad = {};
  bad.depth_max_m = INFINITY;
  EXPECT_THROW(VoxelBlockGridFusion{bad}, std::invalid_argument);

  VoxelBlockGridFusion grid;
  DepthFrame frame;
  frame.depth_m.assign(10, 0.5f);  // not width * height
  EXPECT_THROW(grid.Integrate(frame, T_C_G_at(0.0)), std::invalid_argument);
  frame.depth_m.assign(static_cast<size_t>(frame.intrinsics.width) * frame.intrinsics.height, 0.0f);
  grid.Integrate(frame, T_C_G_at(0.0));
  frame.intrinsics.width /= 2;
  frame.depth_m.resize(static_cast<size_t>(frame.intrinsics.width) * frame.intrinsics.height);
  EXPECT_THROW(grid.Integrate(frame, T_C_G_at(0.0)), std::invalid_argument);
}

// 1 block: a box inside one 24 mm block (16 voxels of 1.5 mm); a 2 mm
// margin reaches the blocks on either side of it on every axis: 3^3.
TEST(VoxelBlockGridFusion, BlocksCoveringCountsTheBlocksAroundABox) {
  fusion::WorkspaceBox box;
  box.min_G = Eigen::Vector3d::Constant(0.001);
  box.max_G = Eigen::Vector3d::Constant(0.023);
  EXPECT_EQ(fusion::BlocksCovering(box, 0.0015, 16, 0.0), 1);
  EXPECT_EQ(fusion::BlocksCovering(box, 0.0015, 16, 0.002), 27);
  EXPECT_EQ(fusion::BlocksCovering(box, 0.0015, 8, 0.0), 8);  // 12 mm blocks: 2 per axis
}

}  // namespace
}  // namespace graspfill
