// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/tsdf_fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "sphere_frames.hpp"

namespace graspfill::fusion {
namespace {

TEST(TsdfFusion, FusedSphereLiesOnTheSphere) {
  TsdfConfig config;
  TsdfFusion fusion(config);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Isometry3d T_C_G = SphereCameraPose(i * 2.0 * M_PI / 12);
    fusion.Integrate(RenderSphere(T_C_G), T_C_G);
  }
  EXPECT_EQ(fusion.frames_integrated(), 12);
  ObjectCloud cloud;
  fusion.ExtractCloud(&cloud);
  ASSERT_GT(cloud.size(), 1000u);
  ASSERT_EQ(cloud.normals_G.size(), cloud.size());
  double max_err = 0.0;
  int normals_outward = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d d = cloud.points_G[i].cast<double>() - kSphereCentreG;
    max_err = std::max(max_err, std::abs(d.norm() - kSphereRadiusM));
    if (cloud.normals_G[i].cast<double>().dot(d.normalized()) > 0.9) ++normals_outward;
    EXPECT_EQ(cloud.provenance[i], Provenance::kObserved);
  }
  // Exact depth: the zero crossing is off by interpolation only (< 1 voxel).
  EXPECT_LT(max_err, config.voxel_m);
  EXPECT_GT(normals_outward, 0.95 * cloud.size());
}

TEST(TsdfFusion, EmptyFramesGiveEmptyCloudAndResetClears) {
  TsdfFusion fusion;
  DepthFrame empty;
  empty.depth_m.assign(640 * 480, 0.0f);
  fusion.Integrate(empty, SphereCameraPose(0.0));
  ObjectCloud cloud;
  fusion.ExtractCloud(&cloud);
  EXPECT_EQ(cloud.size(), 0u);
  fusion.Integrate(RenderSphere(SphereCameraPose(0.0)), SphereCameraPose(0.0));
  fusion.Reset();
  fusion.ExtractCloud(&cloud);
  EXPECT_EQ(cloud.size(), 0u);
}

TEST(TsdfFusion, RejectsBadConfigAndBadFrames) {
  TsdfConfig bad;
  bad.sdf_trunc_m = bad.voxel_m / 2;
  EXPECT_THROW(TsdfFusion{bad}, std::invalid_argument);
  TsdfFusion fusion;
  DepthFrame wrong;
  wrong.depth_m.assign(100, 0.0f);
  EXPECT_THROW(fusion.Integrate(wrong, SphereCameraPose(0.0)), std::invalid_argument);
}

TEST(TsdfFusion, SameFramesGiveIdenticalClouds) {
  ObjectCloud clouds[2];
  for (ObjectCloud& cloud : clouds) {
    TsdfFusion fusion;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Isometry3d T_C_G = SphereCameraPose(i * 0.7);
      fusion.Integrate(RenderSphere(T_C_G), T_C_G);
    }
    fusion.ExtractCloud(&cloud);
  }
  ASSERT_EQ(clouds[0].size(), clouds[1].size());
  EXPECT_TRUE(clouds[0].points_G == clouds[1].points_G);
}

// The product's integration and Open3D's own call (the benchmark's
// reference) fuse the same frames into the same cloud, bit for bit.
TEST(TsdfFusion, IntegrateGivesOpen3DsOwnIntegrationsCloud) {
  TsdfFusion own, open3d;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Isometry3d T_C_G = SphereCameraPose(i * 0.9);
    const DepthFrame frame = RenderSphere(T_C_G);
    own.Integrate(frame, T_C_G);
    open3d.IntegrateUncached(frame, T_C_G);
  }
  EXPECT_EQ(own.frames_integrated(), 5);
  EXPECT_EQ(open3d.frames_integrated(), 5);
  ObjectCloud a, b;
  own.ExtractCloud(&a);
  open3d.ExtractCloud(&b);
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a.points_G == b.points_G);
  EXPECT_TRUE(a.normals_G == b.normals_G);
}

// The cached extraction (only changed units and their neighbours anew)
// equals Open3D's extraction of the whole volume, point for point and
// normal for normal, after every frame of a turn; once the turn has covered
// the sphere, a frame changes only part of the units.
TEST(TsdfFusion, CachedExtractionEqualsOpen3DsAfterEveryFrame) {
  TsdfFusion fusion;
  ObjectCloud cached, full;
  int fewer = 0;
  for (int i = 0; i < 23; ++i) {  // the last frame is extracted
    // A slow turn, the camera 15 deg further each frame.
    const Eigen::Isometry3d T_C_G = SphereCameraPose(i * M_PI / 12);
    fusion.Integrate(RenderSphere(T_C_G), T_C_G);
    if (i % 3 == 2) continue;  // two frames between some extractions
    fusion.ExtractCloud(&cached);
    fusion.ExtractCloudUncached(&full);
    ASSERT_GT(full.size(), 100u);
    ASSERT_EQ(cached.size(), full.size()) << "frame " << i;
    EXPECT_TRUE(cached.points_G == full.points_G) << "frame " << i;
    EXPECT_TRUE(cached.normals_G == full.normals_G) << "frame " << i;
    EXPECT_LE(fusion.units_extracted(), fusion.units());
    fewer += fusion.units_extracted() < fusion.units();
  }
  EXPECT_GT(fewer, 0);  // some extraction reused units
  // An extraction with nothing fused since redoes nothing.
  fusion.ExtractCloud(&cached);
  EXPECT_EQ(fusion.units_extracted(), 0);
  EXPECT_TRUE(cached.points_G == full.points_G);
  // After a reset, nothing is left of the cache.
  fusion.Reset();
  fusion.ExtractCloud(&cached);
  EXPECT_EQ(cached.size(), 0u);
  EXPECT_EQ(fusion.units(), 0);
}

}  // namespace
}  // namespace graspfill::fusion
