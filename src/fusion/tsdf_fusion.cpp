// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/fusion/tsdf_fusion.hpp"

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <open3d/utility/Parallel.h>

#include "frame_size_check.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "sorted_cloud.hpp"
#include "unit_integrator.hpp"
#include "unit_surface_cache.hpp"

#include <cstring>
#include <stdexcept>
#include <vector>

namespace graspfill::fusion {

namespace integration = open3d::pipelines::integration;

void TsdfConfig::Validate() const {
  if (!(voxel_m > 0.0) || !(sdf_trunc_m > voxel_m) || block_resolution < 2 || depth_sampling_stride < 1) {
    throw std::invalid_argument(
        "TsdfConfig: need voxel_m > 0, sdf_trunc_m > voxel_m, "
        "block_resolution >= 2, depth_sampling_stride >= 1");
  }
}

struct TsdfFusion::Impl {
  explicit Impl(const TsdfConfig& c)
      : config(c),
        volume(c.voxel_m, c.sdf_trunc_m, integration::TSDFVolumeColorType::NoColor, c.block_resolution,
               c.depth_sampling_stride) {}
  TsdfConfig config;
  integration::ScalableTSDFVolume volume;
  open3d::geometry::RGBDImage rgbd;  // IntegrateUncached's; depth_ made on its first call, then reused
  open3d::camera::PinholeCameraIntrinsic intrinsic;
  CameraIntrinsics intrinsics_set{0, 0, 0, 0, 0, 0};
  int frames{0};
  // Open3D's Integrate without its per-frame rebuilds (same voxels).
  UnitIntegrator integrator;
  // The last extraction's points per volume unit: logically part of the
  // volume's state, refreshed by the (const) ExtractCloud.
  UnitSurfaceCache surface;
  std::vector<Eigen::Vector3d> points, normals;  // reused
  // The team Open3D's regions name (read once: it looks at the environment).
  int open3d_team{open3d::utility::EstimateMaxThreads()};
};

TsdfFusion::TsdfFusion(const TsdfConfig& config) {
  config.Validate();
  impl_ = std::make_unique<Impl>(config);
}

TsdfFusion::~TsdfFusion() = default;

void TsdfFusion::TakeIntrinsics(const DepthFrame& frame) {
  const CameraIntrinsics& K = frame.intrinsics;
  CheckFrameSize("TsdfFusion::Integrate", frame, impl_->intrinsics_set, impl_->frames);
  if (impl_->intrinsics_set != K) {
    impl_->intrinsic.SetIntrinsics(K.width, K.height, K.fx, K.fy, K.cx, K.cy);
    impl_->intrinsics_set = K;
  }
}

void TsdfFusion::Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G) {
  TakeIntrinsics(frame);
  // Open3D's extrinsic maps world (here G) points into the camera: T_C_G.
  impl_->integrator.Integrate(frame.depth_m, impl_->intrinsic, T_C_G.matrix(), &impl_->volume);
  ++impl_->frames;
}

void TsdfFusion::IntegrateUncached(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G) {
  TakeIntrinsics(frame);
  const CameraIntrinsics& K = frame.intrinsics;
  if (impl_->rgbd.depth_.width_ != K.width || impl_->rgbd.depth_.height_ != K.height) {
    impl_->rgbd.depth_.Prepare(K.width, K.height, 1, 4);
  }
  std::memcpy(impl_->rgbd.depth_.data_.data(), frame.depth_m.data(), frame.depth_m.size() * sizeof(float));
  // Open3D's integration names its own team (a thread per physical core):
  // one thread when the caller allows fewer (core/openmp_threads.hpp).
  const ScopedOpenMpFixedTeam team(impl_->open3d_team);
  impl_->volume.Integrate(impl_->rgbd, impl_->intrinsic, T_C_G.matrix());
  ++impl_->frames;
}

void TsdfFusion::ExtractCloud(ObjectCloud* cloud) const {
  impl_->points.clear();
  impl_->normals.clear();
  impl_->surface.Extract(impl_->volume, &impl_->points, &impl_->normals);
  WriteSortedCloud(impl_->points, impl_->normals, cloud);
}

void TsdfFusion::ExtractCloudUncached(ObjectCloud* cloud) const {
  const ScopedOpenMpFixedTeam team(impl_->open3d_team);
  const std::shared_ptr<open3d::geometry::PointCloud> pcd = impl_->volume.ExtractPointCloud();
  WriteSortedCloud(pcd->points_, pcd->normals_, cloud);
}

int TsdfFusion::units() const { return impl_->surface.units(); }
int TsdfFusion::units_extracted() const { return impl_->surface.units_extracted(); }

void TsdfFusion::Reset() {
  impl_->volume.Reset();
  impl_->integrator.Clear();
  impl_->surface.Clear();
  impl_->frames = 0;
}

const TsdfConfig& TsdfFusion::config() const { return impl_->config; }
int TsdfFusion::frames_integrated() const { return impl_->frames; }

}  // namespace graspfill::fusion
