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
//
// Open3D walks each (x, y) column of voxels along z, adding the z step to
// the column's camera point as it goes. Here the columns of one x take
// their z steps side by side, each column's point the same sum as
// Open3D's, so that the projection (two divisions a voxel, most of the
// time when done voxel by voxel) is a loop the compiler vectorizes. The
// pixels are then read, and the voxels updated, one by one.
void IntegrateUnit(const FrameView& f, integration::UniformTSDFVolume* unit,
                   UnitIntegrator::Scratch* scratch) {
  const float voxel_length_f = static_cast<float>(unit->voxel_length_);
  const float half_voxel_length_f = voxel_length_f * 0.5f;
  const float sdf_trunc_f = static_cast<float>(unit->sdf_trunc_);
  const float sdf_trunc_inv_f = 1.0f / sdf_trunc_f;
  const Eigen::Matrix4f T_scaled = f.T_C_G * voxel_length_f;
  const Eigen::Vector3d& origin = unit->origin_;
  const int n = unit->resolution_;
  scratch->Resize(n);
  float* const cam_x = scratch->cam_x.data();  // [y]: the column's camera point at the slice's z
  float* const cam_y = scratch->cam_y.data();
  float* const cam_z = scratch->cam_z.data();
  float* const depth_of = scratch->voxel_depth.data();   // [z * n + y]: the voxel's camera z
  std::int32_t* const pixel_of = scratch->pixel.data();  // [z * n + y]: its pixel, -1 for none
  const float step_x = T_scaled(0, 2), step_y = T_scaled(1, 2), step_z = T_scaled(2, 2);
  const float fx = f.fx, fy = f.fy, cx = f.cx, cy = f.cy;
  const float safe_width = f.safe_width, safe_height = f.safe_height;
  const std::int32_t width = f.width;
  for (int x = 0; x < n; x++) {
    for (int y = 0; y < n; y++) {
      const Eigen::Vector4f voxel_G(float(half_voxel_length_f + voxel_length_f * x + origin(0)),
                                    float(half_voxel_length_f + voxel_length_f * y + origin(1)),
                                    float(half_voxel_length_f + origin(2)), 1.f);
      const Eigen::Vector4f voxel_C = f.T_C_G * voxel_G;
      cam_x[y] = voxel_C(0);
      cam_y[y] = voxel_C(1);
      cam_z[y] = voxel_C(2);
    }
    for (int z = 0; z < n; z++) {
      float* const depth_z = depth_of + static_cast<size_t>(z) * n;
      std::int32_t* const pixel_z = pixel_of + static_cast<size_t>(z) * n;
      for (int y = 0; y < n; y++) {
        const float vz = cam_z[y];
        const float u_f = cam_x[y] * fx / vz + cx + 0.5f;
        const float v_f = cam_y[y] * fy / vz + cy + 0.5f;
        // & rather than &&: no branches in the loop, so that it vectorizes.
        const bool inside =
            (vz > 0) & (u_f >= 0.0001f) & (u_f < safe_width) & (v_f >= 0.0001f) & (v_f < safe_height);
        const std::int32_t u = static_cast<std::int32_t>(inside ? u_f : 0.0f);
        const std::int32_t v = static_cast<std::int32_t>(inside ? v_f : 0.0f);
        pixel_z[y] = inside ? v * width + u : -1;
        depth_z[y] = vz;
        cam_x[y] += step_x;
        cam_y[y] += step_y;
        cam_z[y] += step_z;
      }
    }
    open3d::geometry::TSDFVoxel* const slice = &unit->voxels_[unit->IndexOf(x, 0, 0)];
    for (int y = 0; y < n; y++) {
      open3d::geometry::TSDFVoxel* const column = slice + static_cast<size_t>(y) * n;
      for (int z = 0; z < n; z++) {
        const size_t at = static_cast<size_t>(z) * n + y;
        const std::int32_t pixel = pixel_of[at];
        if (pixel < 0) continue;
        const float d = f.depth_m[pixel];
        if (d <= 0.0f) continue;
        const float sdf = (d - depth_of[at]) * f.ray_factor[pixel];
        if (sdf > -sdf_trunc_f) {
          open3d::geometry::TSDFVoxel& voxel = column[z];
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
            IntegrateUnit(frame, &OpenUnit(index, volume), &scratch_);
          }
        }
      }
    }
  }
}

}  // namespace graspfill::fusion
