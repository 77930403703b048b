// SPDX-License-Identifier: BSD-3-Clause
// Integrates a depth frame into Open3D's legacy ScalableTSDFVolume as its
// own Integrate() does, without what that call rebuilds for every frame:
//  - the per-pixel factor from z-depth to the ray's length (a float image
//    the size of the frame: 0.47 ms and 1.2 MB at 640 x 480 on this
//    project's machine), made here once per set of intrinsics;
//  - the point cloud of every depth_sampling_stride-th pixel, and the hash
//    set of the units a frame touches (a node allocated per unit), here a
//    stamp per unit that lives as long as the volume.
//  - a call into Open3D's library for each pixel a voxel reads
//    (Image::PointerAt, twice a voxel), and an OpenMP region per unit.
// The units touched, the order they are opened in (and so the volume's own
// map), and each voxel's update (Open3D's
// UniformTSDFVolume::IntegrateWithDepthToCameraDistanceMultiplier, here
// with the pixel reads inlined) are Open3D 0.16's, term for term and in its
// types: the voxels come out bit for bit the same (unit_integrator_test
// checks them against Integrate() after a turn of frames; the
// benchmark keeps Open3D's own call beside this one,
// TsdfFusion::IntegrateUncached).
//
// Private to the fusion module. Single-threaded.
#pragma once

#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <open3d/utility/Helper.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace graspfill::fusion {

class UnitIntegrator {
 public:
  /// ScalableTSDFVolume::Integrate(image, intrinsic, T_C_G) into `volume`
  /// (no colour: graspfill fuses depth alone), for the image whose depth
  /// is `depth_m` [m, row-major, the intrinsic's size; 0 = no return]: read
  /// where it lies, not copied into an Open3D image first.
  /// @throws std::invalid_argument on another size or a colour volume.
  void Integrate(const std::vector<float>& depth_m, const open3d::camera::PinholeCameraIntrinsic& intrinsic,
                 const Eigen::Matrix4d& T_C_G, open3d::pipelines::integration::ScalableTSDFVolume* volume);
  /// Forgets the units (the volume was reset).
  void Clear() { last_frame_.clear(); }

  /// A unit's projected voxels, one x slice at a time: kept, so that a
  /// frame allocates nothing.
  struct Scratch {
    std::vector<float> cam_x, cam_y, cam_z, voxel_depth;
    std::vector<std::int32_t> pixel;
    void Resize(int resolution) {
      const size_t n = static_cast<size_t>(resolution);
      if (cam_x.size() == n) return;
      cam_x.assign(n, 0.0f);
      cam_y.assign(n, 0.0f);
      cam_z.assign(n, 0.0f);
      voxel_depth.assign(n * n, 0.0f);
      pixel.assign(n * n, -1);
    }
  };

 private:
  Scratch scratch_;
  std::shared_ptr<open3d::geometry::Image> ray_factor_;  // for ray_factor_intrinsic_
  open3d::camera::PinholeCameraIntrinsic ray_factor_intrinsic_;
  // Per unit the last frame that integrated it (frames count from 1).
  std::unordered_map<Eigen::Vector3i, std::uint64_t, open3d::utility::hash_eigen<Eigen::Vector3i>>
      last_frame_;
  std::uint64_t frame_{0};
};

}  // namespace graspfill::fusion
