// SPDX-License-Identifier: BSD-3-Clause
// Fuses masked depth frames into a TSDF volume in the gripper frame G
// (Open3D's ScalableTSDFVolume: voxel blocks allocated only where depth
// lands, so a cropped frame costs only the object's blocks).
//
// Threads: Open3D runs an OpenMP team of a thread per physical core per
// voxel block, whatever omp_set_num_threads says. On 2 cores with anything
// else running, those barriers made a frame 15-30x slower (131-223 ms vs
// 6-9 ms measured with `graspfill replay`). Integrate runs that team on one
// thread when the calling thread's OpenMP count is below it; the Pipeline
// sets the count per call (PipelineConfig::num_threads, default 1;
// core/openmp_threads.hpp).
#pragma once

#include <Eigen/Geometry>
#include <memory>

#include "graspfill/types.hpp"

namespace graspfill::fusion {

struct TsdfConfig {
  /// Voxel edge [m]. 1.5 mm keeps the extracted surface within ~1 mm of a
  /// 5-10 cm object seen at 0.5 m while staying real time.
  double voxel_m{0.0015};
  /// Truncation distance [m]: about 4 voxels, > 3 sigma of the sensor noise
  /// at 0.5 m (sigma ~ 1.2 mm).
  double sdf_trunc_m{0.006};
  /// Voxels per block edge (Open3D's volume unit resolution).
  int block_resolution{16};
  /// Open3D uses every n-th pixel to find the blocks a frame touches.
  int depth_sampling_stride{2};

  /// Throws std::invalid_argument on a non-positive or inconsistent value.
  void Validate() const;
};

class TsdfFusion {
 public:
  explicit TsdfFusion(const TsdfConfig& config = {});
  ~TsdfFusion();
  TsdfFusion(const TsdfFusion&) = delete;
  TsdfFusion& operator=(const TsdfFusion&) = delete;

  /// Integrates one frame (0 = no depth) taken with the gripper at T_C_G.
  /// The frame's size must stay the same between calls (else throws).
  void Integrate(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G);
  /// The same by Open3D's own ScalableTSDFVolume::Integrate, which rebuilds
  /// per frame what Integrate keeps (the reference for the tests and the
  /// benchmark): the same voxels, bit for bit.
  void IntegrateUncached(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G);

  /// Writes the zero crossings of the TSDF (points and normals in G, all
  /// observed) into *cloud, replacing its points.
  /// Only the volume units whose voxels changed since the last call (and
  /// their neighbours) are extracted anew; the rest come from the last
  /// call. The result equals ExtractCloudUncached's, point for point.
  void ExtractCloud(ObjectCloud* cloud) const;
  /// The same from Open3D's ExtractPointCloud over the whole volume (the
  /// reference for the tests and the benchmark).
  void ExtractCloudUncached(ObjectCloud* cloud) const;
  /// Volume units at the last ExtractCloud, and those it extracted anew.
  int units() const;
  int units_extracted() const;

  /// Empties the volume (a new object).
  void Reset();

  const TsdfConfig& config() const;
  int frames_integrated() const;

 private:
  // Checks the frame's size and takes its intrinsics (once per set).
  void TakeIntrinsics(const DepthFrame& frame);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::fusion
