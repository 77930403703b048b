// SPDX-License-Identifier: BSD-3-Clause
// Open3D's tensor TSDF, t::geometry::VoxelBlockGrid, fusing the same masked
// depth frames as TsdfFusion (Open3D's legacy ScalableTSDFVolume), so that
// `graspfill bench` can time the two side by side and compare their clouds
// (issue 39, "the integrator").
//
// Not the product's integrator: a tool library of the CLI and the tests
// (graspfill_voxel_block_grid, neither exported nor installed). It lives in
// the fusion module to share its canonical cloud order (sorted_cloud.hpp);
// Open3D stays behind this header, as behind tsdf_fusion.hpp.
//
// Differences from TsdfFusion that a comparison must allow for:
//  - voxels sit at integer multiples of voxel_m (ScalableTSDFVolume's at
//    their centres, half a voxel further), so the two grids sample the
//    same surface at other points;
//  - the signed distance is measured along the camera's z (the legacy
//    volume's along the ray), which changes a voxel's value off the optical
//    axis but not where it crosses zero;
//  - a voxel reads the depth of the pixel its projection falls in, not the
//    nearest (nearest_pixel corrects it);
//  - the blocks a frame touches come from every 4th pixel (legacy: every
//    depth_sampling_stride-th), each along its ray over +-sdf_trunc_m;
//  - the extraction keeps every sign change between observed voxels
//    (legacy: only those with |tsdf| < 0.98 at the voxel).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>

#include "graspfill/fusion/tsdf_fusion.hpp"
#include "graspfill/fusion/workspace_crop.hpp"
#include "graspfill/types.hpp"

namespace graspfill::fusion {

struct VoxelBlockGridConfig {
  /// Voxel edge and truncation [m]: the product's (TsdfConfig's defaults).
  double voxel_m{0.0015};
  double sdf_trunc_m{0.006};
  /// Voxels per block edge (8 or 16 in Open3D's examples).
  int block_resolution{16};
  /// Blocks the hash map holds before it grows (growing copies every
  /// block). 0: enough for the default WorkspaceBox grown by sdf_trunc_m.
  int64_t block_count{0};
  /// Depth beyond this is not integrated [m]. The frames come cropped to
  /// the workspace box (at most ~0.6 m away on the rig), so the limit only
  /// has to be finite: Open3D walks each ray's band up to it.
  double depth_max_m{3.0};
  /// Open3D's tensor integration reads a voxel's depth at the pixel its
  /// projection falls in (the floor), half a pixel off the nearest one the
  /// legacy volume reads: on tests/fusion's sphere that took the cloud's
  /// p95 distance to the truth from 0.20 to 0.68 mm. true: the principal
  /// point given to Integrate moves by half a pixel, so that the floor is
  /// the nearest.
  bool nearest_pixel{true};
  /// ExtractCloud keeps zero crossings between voxels of weight above
  /// this: 0 keeps every observed voxel, as ScalableTSDFVolume does.
  double weight_threshold{0.0};

  /// The product's voxel and truncation from `tsdf`, blocks of
  /// `block_resolution` voxels, block_count sized for `workspace`.
  static VoxelBlockGridConfig Like(const TsdfConfig& tsdf, int block_resolution,
                                   const WorkspaceBox& workspace = {});
  /// Throws std::invalid_argument on a non-positive or inconsistent value.
  void Validate() const;
};

/// Blocks of `block_resolution` voxels of `voxel_m` that cover `box`
/// grown by `margin_m` on every side.
int64_t BlocksCovering(const WorkspaceBox& box, double voxel_m, int block_resolution, double margin_m);

class VoxelBlockGridFusion {
 public:
  /// Throws std::invalid_argument on a bad config.
  explicit VoxelBlockGridFusion(const VoxelBlockGridConfig& config = {});
  ~VoxelBlockGridFusion();
  VoxelBlockGridFusion(const VoxelBlockGridFusion&) = delete;
  VoxelBlockGridFusion& operator=(const VoxelBlockGridFusion&) = delete;

  /// Integrates one frame (0 = no depth) taken with the camera at T_C_G
  /// (G: the volume's frame): the blocks in the frame's truncation band
  /// are found, allocated, then updated. Its OpenMP regions follow the
  /// calling thread's count as TsdfFusion's do (core/openmp_threads.hpp).
  /// The frame's size must stay the same between calls (else throws).
  void Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G);

  /// The zero crossings over the whole grid (Open3D's ExtractPointCloud),
  /// points and unit normals in G, in TsdfFusion's canonical order.
  void ExtractCloud(ObjectCloud* cloud) const;

  /// Blocks allocated so far.
  int64_t blocks() const;
  int frames_integrated() const;
  const VoxelBlockGridConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::fusion
