// SPDX-License-Identifier: BSD-3-Clause
// The fusion's own integration loop (src/fusion/unit_integrator.hpp) gives
// Open3D's ScalableTSDFVolume::Integrate's voxels bit for bit, in the same
// units opened in the same order, and allocates nothing for a frame whose
// units exist, where Open3D's own call allocates on every frame.
#include "unit_integrator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <open3d/pipelines/integration/UniformTSDFVolume.h>

#include "../allocation_count.hpp"
#include "graspfill/fusion/tsdf_fusion.hpp"
#include "sphere_frames.hpp"

namespace graspfill::fusion {
namespace {

namespace integration = open3d::pipelines::integration;

// The test's camera: fx and fy unequal, so that a swapped pair shows.
CameraIntrinsics Intrinsics() {
  CameraIntrinsics K;
  K.fy = 523.0;
  K.cy = 241.0;
  return K;
}

// The sphere's frame, with a band of pixels cut out as the claw's would
// be: its depth as the product holds it, and as Open3D's image.
struct SphereFrame {
  std::vector<float> depth_m;
  open3d::geometry::RGBDImage image;
};

SphereFrame RenderSphereFrame(const Eigen::Matrix4d& T_C_G) {
  SphereFrame f;
  f.depth_m = RenderSphere(Eigen::Isometry3d(T_C_G), Intrinsics()).depth_m;
  const CameraIntrinsics K = Intrinsics();
  for (int v = 0; v < K.height; ++v) {
    for (int u = 301; u < 320; ++u) f.depth_m[static_cast<size_t>(v) * K.width + u] = 0.0f;  // the cut-out
  }
  f.image.depth_.Prepare(K.width, K.height, 1, 4);
  std::copy(f.depth_m.begin(), f.depth_m.end(), f.image.depth_.PointerAt<float>(0, 0));
  return f;
}

Eigen::Matrix4d CameraPose(double angle, double elevation) {
  return SphereCameraPose(angle, elevation).matrix();
}

integration::ScalableTSDFVolume MakeVolume() {
  const TsdfConfig config;  // the product's voxel, truncation, unit and stride
  return integration::ScalableTSDFVolume(config.voxel_m, config.sdf_trunc_m,
                                         integration::TSDFVolumeColorType::NoColor, config.block_resolution,
                                         config.depth_sampling_stride);
}

const CameraIntrinsics kK = Intrinsics();
const open3d::camera::PinholeCameraIntrinsic kIntrinsic(kK.width, kK.height, kK.fx, kK.fy, kK.cx, kK.cy);

TEST(UnitIntegrator, VoxelsAreOpen3DsIntegrateBitForBit) {
  integration::ScalableTSDFVolume open3d_volume = MakeVolume(), own_volume = MakeVolume();
  UnitIntegrator integrator;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Matrix4d T_C_G = CameraPose(0.45 * i, 0.2 * std::sin(i));
    const SphereFrame frame = RenderSphereFrame(T_C_G);
    open3d_volume.Integrate(frame.image, kIntrinsic, T_C_G);
    integrator.Integrate(frame.depth_m, kIntrinsic, T_C_G, &own_volume);
  }
  ASSERT_GT(open3d_volume.volume_units_.size(), 20u);
  ASSERT_EQ(own_volume.volume_units_.size(), open3d_volume.volume_units_.size());
  // The same map, built in the same order: it iterates alike (the cached
  // extraction and the canonical sort make the cloud's order the caller's
  // anyway, but Open3D's own extraction walks this map).
  auto a = open3d_volume.volume_units_.begin();
  auto b = own_volume.volume_units_.begin();
  long observed = 0;
  for (; a != open3d_volume.volume_units_.end(); ++a, ++b) {
    ASSERT_EQ(a->first, b->first);
    ASSERT_EQ(b->second.index_, a->first);
    const auto& va = a->second.volume_->voxels_;
    const auto& vb = b->second.volume_->voxels_;
    ASSERT_EQ(va.size(), vb.size());
    for (size_t k = 0; k < va.size(); ++k) {
      ASSERT_EQ(va[k].tsdf_, vb[k].tsdf_) << "unit " << a->first.transpose() << " voxel " << k;
      ASSERT_EQ(va[k].weight_, vb[k].weight_) << "unit " << a->first.transpose() << " voxel " << k;
      observed += va[k].weight_ > 0.0f;
    }
  }
  EXPECT_GT(observed, 10000);
}

TEST(UnitIntegrator, AFrameWhoseUnitsExistAllocatesNothing) {
  const Eigen::Matrix4d T_C_G = CameraPose(0.3, 0.1);
  const SphereFrame frame = RenderSphereFrame(T_C_G);
  integration::ScalableTSDFVolume own_volume = MakeVolume(), open3d_volume = MakeVolume();
  UnitIntegrator integrator;
  integrator.Integrate(frame.depth_m, kIntrinsic, T_C_G, &own_volume);  // makes the units and the ray factors
  long before = graspfill::testing::Allocations();
  integrator.Integrate(frame.depth_m, kIntrinsic, T_C_G, &own_volume);
  EXPECT_EQ(graspfill::testing::Allocations() - before, 0);
  // Open3D's own call, its units made too, allocates on every frame (its
  // ray factors, its point cloud, its set of units): what the test guards.
  open3d_volume.Integrate(frame.image, kIntrinsic, T_C_G);
  before = graspfill::testing::Allocations();
  open3d_volume.Integrate(frame.image, kIntrinsic, T_C_G);
  EXPECT_GT(graspfill::testing::Allocations() - before, 2);
}

TEST(UnitIntegrator, OtherIntrinsicsGetTheirOwnRayFactorsAndBadImagesAreRefused) {
  // The same frame under intrinsics changed half-way through: the voxels
  // still match Open3D's, which makes the ray factors for every frame.
  const open3d::camera::PinholeCameraIntrinsic other(kK.width, kK.height, 1.1 * kK.fx, 1.1 * kK.fy,
                                                     kK.cx + 7.0, kK.cy);
  integration::ScalableTSDFVolume open3d_volume = MakeVolume(), own_volume = MakeVolume();
  UnitIntegrator integrator;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Matrix4d T_C_G = CameraPose(0.8 * i, 0.0);
    const SphereFrame frame = RenderSphereFrame(T_C_G);
    const open3d::camera::PinholeCameraIntrinsic& K = i < 2 ? kIntrinsic : other;
    open3d_volume.Integrate(frame.image, K, T_C_G);
    integrator.Integrate(frame.depth_m, K, T_C_G, &own_volume);
  }
  ASSERT_EQ(own_volume.volume_units_.size(), open3d_volume.volume_units_.size());
  for (const auto& [index, unit] : open3d_volume.volume_units_) {
    const auto own = own_volume.volume_units_.find(index);
    ASSERT_NE(own, own_volume.volume_units_.end());
    for (size_t k = 0; k < unit.volume_->voxels_.size(); ++k) {
      ASSERT_EQ(unit.volume_->voxels_[k].tsdf_, own->second.volume_->voxels_[k].tsdf_);
    }
  }
  // A depth image of another size than the intrinsic's, none at all, or a
  // volume with colour.
  const std::vector<float> small(320 * 240, 0.5f);
  EXPECT_THROW(integrator.Integrate(small, kIntrinsic, Eigen::Matrix4d::Identity(), &own_volume),
               std::invalid_argument);
  EXPECT_THROW(integrator.Integrate({}, kIntrinsic, Eigen::Matrix4d::Identity(), &own_volume),
               std::invalid_argument);
  const TsdfConfig config;
  integration::ScalableTSDFVolume coloured(config.voxel_m, config.sdf_trunc_m,
                                           integration::TSDFVolumeColorType::RGB8);
  const SphereFrame frame = RenderSphereFrame(CameraPose(0.0, 0.0));
  EXPECT_THROW(integrator.Integrate(frame.depth_m, kIntrinsic, Eigen::Matrix4d::Identity(), &coloured),
               std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::fusion
