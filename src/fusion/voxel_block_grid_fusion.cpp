// SPDX-License-Identifier: BSD-3-Clause
#include "voxel_block_grid_fusion.hpp"

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/Image.h>
#include <open3d/t/geometry/PointCloud.h>
#include <open3d/t/geometry/VoxelBlockGrid.h>
#include <open3d/utility/Parallel.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "frame_size_check.hpp"
#include "graspfill/core/openmp_threads.hpp"
#include "sorted_cloud.hpp"

namespace graspfill::fusion {

namespace core = open3d::core;
namespace tgeometry = open3d::t::geometry;

namespace {

// GetUniqueBlockCoordinates looks at every 4th pixel of every 4th row
// (Open3D 0.16's down factor) and throws when none holds depth.
constexpr int kOpen3dTouchStride = 4;

bool AnyTouchSample(const DepthFrame& frame, double depth_max_m) {
  const CameraIntrinsics& K = frame.intrinsics;
  for (int v = 0; v < K.height / kOpen3dTouchStride; ++v) {
    for (int u = 0; u < K.width / kOpen3dTouchStride; ++u) {
      const float d = frame.at(u * kOpen3dTouchStride, v * kOpen3dTouchStride);
      if (d > 0.0f && d < depth_max_m) return true;
    }
  }
  return false;
}

}  // namespace

int64_t BlocksCovering(const WorkspaceBox& box, double voxel_m, int block_resolution, double margin_m) {
  const double block_m = voxel_m * block_resolution;
  int64_t count = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const auto first = static_cast<int64_t>(std::floor((box.min_G[axis] - margin_m) / block_m));
    const auto last = static_cast<int64_t>(std::floor((box.max_G[axis] + margin_m) / block_m));
    count *= last - first + 1;
  }
  return count;
}

VoxelBlockGridConfig VoxelBlockGridConfig::Like(const TsdfConfig& tsdf, int block_resolution,
                                                const WorkspaceBox& workspace) {
  VoxelBlockGridConfig c;
  c.voxel_m = tsdf.voxel_m;
  c.sdf_trunc_m = tsdf.sdf_trunc_m;
  c.block_resolution = block_resolution;
  c.block_count = BlocksCovering(workspace, tsdf.voxel_m, block_resolution, tsdf.sdf_trunc_m);
  return c;
}

void VoxelBlockGridConfig::Validate() const {
  if (!(voxel_m > 0.0) || !(sdf_trunc_m > voxel_m) || block_resolution < 2 || block_count < 0 ||
      !(depth_max_m > 0.0) || !std::isfinite(depth_max_m) || !(weight_threshold >= 0.0)) {
    throw std::invalid_argument(
        "VoxelBlockGridConfig: need voxel_m > 0, sdf_trunc_m > voxel_m, block_resolution >= 2, "
        "block_count >= 0, a finite depth_max_m > 0, weight_threshold >= 0");
  }
}

struct VoxelBlockGridFusion::Impl {
  explicit Impl(const VoxelBlockGridConfig& c)
      : config(c),
        grid({"tsdf", "weight"}, {core::Float32, core::Float32}, {{1}, {1}}, static_cast<float>(c.voxel_m),
             c.block_resolution,
             c.block_count > 0 ? c.block_count
                               : BlocksCovering({}, c.voxel_m, c.block_resolution, c.sdf_trunc_m),
             core::Device("CPU:0")),
        extrinsic(core::Tensor::Eye(4, core::Float64, core::Device("CPU:0"))) {}
  VoxelBlockGridConfig config;
  tgeometry::VoxelBlockGrid grid;
  // Reused across frames: the depth in meters (H x W x 1) and T_C_G.
  core::Tensor depth;
  core::Tensor intrinsic;            // the camera's, to find the blocks
  core::Tensor intrinsic_integrate;  // nearest_pixel's shift applied
  core::Tensor extrinsic;
  CameraIntrinsics intrinsics_set{0, 0, 0, 0, 0, 0};
  int frames{0};
  std::vector<Eigen::Vector3d> points, normals;  // reused
  // The team Open3D's regions name (read once: it looks at the environment).
  int open3d_team{open3d::utility::EstimateMaxThreads()};
};

VoxelBlockGridFusion::VoxelBlockGridFusion(const VoxelBlockGridConfig& config) {
  config.Validate();
  impl_ = std::make_unique<Impl>(config);
}

VoxelBlockGridFusion::~VoxelBlockGridFusion() = default;

void VoxelBlockGridFusion::Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G) {
  const CameraIntrinsics& K = frame.intrinsics;
  Impl& m = *impl_;
  CheckFrameSize("VoxelBlockGridFusion::Integrate", frame, m.intrinsics_set, m.frames);
  if (m.intrinsics_set != K) {
    m.intrinsic = core::Tensor::Init<double>({{K.fx, 0.0, K.cx}, {0.0, K.fy, K.cy}, {0.0, 0.0, 1.0}});
    // Open3D's tensor integration reads the pixel at floor(u), floor(v)
    // (the legacy one the nearest): half a pixel on the principal point
    // makes the floor the nearest.
    const double shift_px = m.config.nearest_pixel ? 0.5 : 0.0;
    m.intrinsic_integrate = core::Tensor::Init<double>(
        {{K.fx, 0.0, K.cx + shift_px}, {0.0, K.fy, K.cy + shift_px}, {0.0, 0.0, 1.0}});
    m.depth = core::Tensor({K.height, K.width, 1}, core::Float32, core::Device("CPU:0"));
    m.intrinsics_set = K;
  }
  ++m.frames;
  // Open3D would throw on a frame none of whose samples holds depth.
  if (!AnyTouchSample(frame, m.config.depth_max_m)) return;
  std::memcpy(m.depth.GetDataPtr<float>(), frame.depth_m.data(), frame.depth_m.size() * sizeof(float));
  // Open3D's extrinsic maps world (here G) points into the camera: T_C_G,
  // row-major.
  double* e = m.extrinsic.GetDataPtr<double>();
  const Eigen::Matrix4d T = T_C_G.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) e[4 * r + c] = T(r, c);
  }
  const tgeometry::Image depth_image(m.depth);
  const auto depth_max = static_cast<float>(m.config.depth_max_m);
  const auto trunc_voxels = static_cast<float>(m.config.sdf_trunc_m / m.config.voxel_m);
  constexpr float kDepthScale = 1.0f;  // the depth is in meters already
  // Open3D's regions name their own team: one thread when the caller
  // allows fewer (core/openmp_threads.hpp).
  const ScopedOpenMpFixedTeam team(m.open3d_team);
  const core::Tensor blocks = m.grid.GetUniqueBlockCoordinates(depth_image, m.intrinsic, m.extrinsic,
                                                               kDepthScale, depth_max, trunc_voxels);
  m.grid.Integrate(blocks, depth_image, m.intrinsic_integrate, m.extrinsic, kDepthScale, depth_max,
                   trunc_voxels);
}

void VoxelBlockGridFusion::ExtractCloud(ObjectCloud* cloud) const {
  Impl& m = *impl_;
  m.points.clear();
  m.normals.clear();
  if (blocks() > 0) {
    const ScopedOpenMpFixedTeam team(m.open3d_team);
    const tgeometry::PointCloud pcd = m.grid.ExtractPointCloud(static_cast<float>(m.config.weight_threshold));
    const core::Tensor positions = pcd.GetPointPositions().Contiguous();
    const core::Tensor normals = pcd.GetPointNormals().Contiguous();
    const int64_t n = positions.GetLength();
    const float* p = positions.GetDataPtr<float>();
    const float* q = normals.GetDataPtr<float>();
    m.points.reserve(n);
    m.normals.reserve(n);
    for (int64_t i = 0; i < n; ++i) {
      m.points.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      m.normals.emplace_back(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
    }
  }
  WriteSortedCloud(m.points, m.normals, cloud);
}

int64_t VoxelBlockGridFusion::blocks() const { return impl_->grid.GetHashMap().Size(); }
int VoxelBlockGridFusion::frames_integrated() const { return impl_->frames; }
const VoxelBlockGridConfig& VoxelBlockGridFusion::config() const { return impl_->config; }

}  // namespace graspfill::fusion
