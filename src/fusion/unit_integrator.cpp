// SPDX-License-Identifier: BSD-3-Clause
#include "unit_integrator.hpp"

#include <open3d/pipelines/integration/UniformTSDFVolume.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

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

// What Open3D's per-unit update reads of a frame, in its own types.
struct FrameView {
  const float* depth_m;     // row-major, width x height
  const float* ray_factor;  // likewise
  int width, height;
  float fx, fy, cx, cy;
  Eigen::Matrix4f T_C_G;
  float safe_width, safe_height;  // the last column and row a voxel may land in

  FrameView(const std::vector<float>& depth, const open3d::geometry::Image& factor,
            const open3d::camera::PinholeCameraIntrinsic& intrinsic, const Eigen::Matrix4d& T_C_G_d)
      : depth_m(depth.data()),
        ray_factor(reinterpret_cast<const float*>(factor.data_.data())),
        width(intrinsic.width_),
        height(intrinsic.height_),
        fx(static_cast<float>(intrinsic.GetFocalLength().first)),
        fy(static_cast<float>(intrinsic.GetFocalLength().second)),
        cx(static_cast<float>(intrinsic.GetPrincipalPoint().first)),
        cy(static_cast<float>(intrinsic.GetPrincipalPoint().second)),
        T_C_G(T_C_G_d.cast<float>()),
        safe_width(intrinsic.width_ - 0.0001f),
        safe_height(intrinsic.height_ - 0.0001f) {}
};

// Open3D 0.16's UniformTSDFVolume::IntegrateWithDepthToCameraDistanceMultiplier
// (no colour), term for term and in its types, so every voxel gets the
// same bits; the pixel reads inlined, where Open3D calls into its library
// for each (Image::PointerAt). One thread, as the product runs Open3D's.
void IntegrateUnit(const FrameView& f, integration::UniformTSDFVolume* unit) {
  const float voxel_length_f = static_cast<float>(unit->voxel_length_);
  const float half_voxel_length_f = voxel_length_f * 0.5f;
  const float sdf_trunc_f = static_cast<float>(unit->sdf_trunc_);
  const float sdf_trunc_inv_f = 1.0f / sdf_trunc_f;
  const Eigen::Matrix4f T_scaled = f.T_C_G * voxel_length_f;
  const Eigen::Vector3d& origin = unit->origin_;
  const int n = unit->resolution_;
  for (int x = 0; x < n; x++) {
    for (int y = 0; y < n; y++) {
      const Eigen::Vector4f voxel_G(float(half_voxel_length_f + voxel_length_f * x + origin(0)),
                                    float(half_voxel_length_f + voxel_length_f * y + origin(1)),
                                    float(half_voxel_length_f + origin(2)), 1.f);
      Eigen::Vector4f voxel_C = f.T_C_G * voxel_G;
      for (int z = 0; z < n;
           z++, voxel_C(0) += T_scaled(0, 2), voxel_C(1) += T_scaled(1, 2), voxel_C(2) += T_scaled(2, 2)) {
        if (voxel_C(2) <= 0) continue;
        const float u_f = voxel_C(0) * f.fx / voxel_C(2) + f.cx + 0.5f;
        const float v_f = voxel_C(1) * f.fy / voxel_C(2) + f.cy + 0.5f;
        if (!(u_f >= 0.0001f && u_f < f.safe_width && v_f >= 0.0001f && v_f < f.safe_height)) continue;
        const size_t pixel = static_cast<size_t>(static_cast<int>(v_f)) * f.width + static_cast<int>(u_f);
        const float d = f.depth_m[pixel];
        if (d <= 0.0f) continue;
        const float sdf = (d - voxel_C(2)) * f.ray_factor[pixel];
        if (sdf > -sdf_trunc_f) {
          open3d::geometry::TSDFVoxel& voxel = unit->voxels_[unit->IndexOf(x, y, z)];
          const float tsdf = std::min(1.0f, sdf * sdf_trunc_inv_f);
          voxel.tsdf_ = (voxel.tsdf_ * voxel.weight_ + tsdf) / (voxel.weight_ + 1.0f);
          voxel.weight_ += 1.0f;
        }
      }
    }
  }
}

}  // namespace

void UnitIntegrator::Integrate(const std::vector<float>& depth_m,
                               const open3d::camera::PinholeCameraIntrinsic& intrinsic,
                               const Eigen::Matrix4d& T_C_G, integration::ScalableTSDFVolume* volume) {
  if (intrinsic.width_ <= 0 || intrinsic.height_ <= 0 ||
      depth_m.size() != static_cast<size_t>(intrinsic.width_) * static_cast<size_t>(intrinsic.height_) ||
      volume->color_type_ != integration::TSDFVolumeColorType::NoColor) {
    throw std::invalid_argument("UnitIntegrator: needs a depth image of the intrinsic's size, no colour");
  }
  if (!ray_factor_ || !SameIntrinsic(ray_factor_intrinsic_, intrinsic)) {
    ray_factor_ = open3d::geometry::Image::CreateDepthToCameraDistanceMultiplierFloatImage(intrinsic);
    ray_factor_intrinsic_ = intrinsic;
  }
  ++frame_;
  const FrameView frame(depth_m, *ray_factor_, intrinsic, T_C_G);
  // Open3D's pixel to point (PointCloud::CreateFromDepthImage, float
  // depth): the same expressions, so the same bits, and the same units.
  const Eigen::Matrix4d T_G_C = T_C_G.inverse();
  const std::pair<double, double> focal = intrinsic.GetFocalLength();
  const std::pair<double, double> principal = intrinsic.GetPrincipalPoint();
  const double trunc = volume->sdf_trunc_;
  const double unit_m = volume->volume_unit_length_;
  const int stride = volume->depth_sampling_stride_;
  for (int i = 0; i < frame.height; i += stride) {
    for (int j = 0; j < frame.width; j += stride) {
      const float d = frame.depth_m[static_cast<size_t>(i) * frame.width + j];
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
            IntegrateUnit(frame, &OpenUnit(index, volume));
          }
        }
      }
    }
  }
}

}  // namespace graspfill::fusion
