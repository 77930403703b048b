// SPDX-License-Identifier: BSD-3-Clause
#include "unit_integrator.hpp"

#include <open3d/pipelines/integration/UniformTSDFVolume.h>

#include <cmath>
#include <stdexcept>

namespace graspfill::fusion {
namespace {

namespace integration = open3d::pipelines::integration;

bool SameIntrinsic(const open3d::camera::PinholeCameraIntrinsic& a,
                   const open3d::camera::PinholeCameraIntrinsic& b) {
  return a.width_ == b.width_ && a.height_ == b.height_ && a.intrinsic_matrix_ == b.intrinsic_matrix_;
}

// The unit holding `point` (Open3D's LocateVolumeUnit).
Eigen::Vector3i UnitOf(const Eigen::Vector3d& point, double unit_m) {
  return Eigen::Vector3i(static_cast<int>(std::floor(point(0) / unit_m)),
                         static_cast<int>(std::floor(point(1) / unit_m)),
                         static_cast<int>(std::floor(point(2) / unit_m)));
}

// The unit at `index`, made when new (Open3D's OpenVolumeUnit).
integration::UniformTSDFVolume& OpenUnit(const Eigen::Vector3i& index,
                                         integration::ScalableTSDFVolume* volume) {
  integration::ScalableTSDFVolume::VolumeUnit& unit = volume->volume_units_[index];
  if (!unit.volume_) {
    unit.volume_ = std::make_shared<integration::UniformTSDFVolume>(
        volume->volume_unit_length_, volume->volume_unit_resolution_, volume->sdf_trunc_, volume->color_type_,
        index.cast<double>() * volume->volume_unit_length_);
    unit.index_ = index;
  }
  return *unit.volume_;
}

}  // namespace

void UnitIntegrator::Integrate(const open3d::geometry::RGBDImage& image,
                               const open3d::camera::PinholeCameraIntrinsic& intrinsic,
                               const Eigen::Matrix4d& T_C_G, integration::ScalableTSDFVolume* volume) {
  const open3d::geometry::Image& depth = image.depth_;
  if (depth.num_of_channels_ != 1 || depth.bytes_per_channel_ != 4 || depth.width_ != intrinsic.width_ ||
      depth.height_ != intrinsic.height_ ||
      volume->color_type_ != integration::TSDFVolumeColorType::NoColor) {
    throw std::invalid_argument(
        "UnitIntegrator: needs a float depth image of the intrinsic's size, no colour");
  }
  if (!ray_factor_ || !SameIntrinsic(ray_factor_intrinsic_, intrinsic)) {
    ray_factor_ = open3d::geometry::Image::CreateDepthToCameraDistanceMultiplierFloatImage(intrinsic);
    ray_factor_intrinsic_ = intrinsic;
  }
  ++frame_;
  // Open3D's pixel to point (PointCloud::CreateFromDepthImage, float
  // depth): the same expressions, so the same bits, and the same units.
  const Eigen::Matrix4d T_G_C = T_C_G.inverse();
  const std::pair<double, double> focal = intrinsic.GetFocalLength();
  const std::pair<double, double> principal = intrinsic.GetPrincipalPoint();
  const double trunc = volume->sdf_trunc_;
  const double unit_m = volume->volume_unit_length_;
  const int stride = volume->depth_sampling_stride_;
  for (int i = 0; i < depth.height_; i += stride) {
    for (int j = 0; j < depth.width_; j += stride) {
      const float d = *depth.PointerAt<float>(j, i);
      if (!(d > 0)) continue;
      const double z = static_cast<double>(d);
      const double x = (j - principal.first) * z / focal.first;
      const double y = (i - principal.second) * z / focal.second;
      const Eigen::Vector4d point_h = T_G_C * Eigen::Vector4d(x, y, z, 1.0);
      const Eigen::Vector3d point = point_h.head<3>();
      const Eigen::Vector3i lo = UnitOf(point - Eigen::Vector3d(trunc, trunc, trunc), unit_m);
      const Eigen::Vector3i hi = UnitOf(point + Eigen::Vector3d(trunc, trunc, trunc), unit_m);
      for (int ux = lo(0); ux <= hi(0); ++ux) {
        for (int uy = lo(1); uy <= hi(1); ++uy) {
          for (int uz = lo(2); uz <= hi(2); ++uz) {
            const Eigen::Vector3i index(ux, uy, uz);
            std::uint64_t& last = last_frame_[index];
            if (last == frame_) continue;  // this frame has integrated it
            last = frame_;
            OpenUnit(index, volume)
                .IntegrateWithDepthToCameraDistanceMultiplier(image, intrinsic, T_C_G, *ray_factor_);
          }
        }
      }
    }
  }
}

}  // namespace graspfill::fusion
