// SPDX-License-Identifier: BSD-3-Clause
// The TSDF's zero crossings kept per volume unit of Open3D's
// ScalableTSDFVolume, so that an extraction redoes only the units whose
// voxels changed since the last one (issue 10: the live loop extracts a
// cloud every few frames, and most of the volume has not changed).
//
// A unit's points depend on its voxels and on its 26 neighbours' (a
// crossing towards the next unit, the normal's trilinear samples up to two
// voxels away), so a changed unit makes its neighbours dirty too. A unit
// changed when the sum of its voxels' weights did: every integration that
// touches a voxel adds to its weight (nothing ever lowers one but Reset).
// The points and normals are computed with Open3D's legacy extraction's
// arithmetic, term for term, so the result equals
// ScalableTSDFVolume::ExtractPointCloud() bit for bit (as a set: the order
// is the caller's; tsdf_fusion_test checks it after every update).
//
// Private to the fusion module. Single-threaded.
#pragma once

#include <open3d/pipelines/integration/ScalableTSDFVolume.h>

#include <Eigen/Core>
#include <unordered_map>
#include <vector>

namespace graspfill::fusion {

class UnitSurfaceCache {
 public:
  /// Brings the cache up to date with `volume` and appends every unit's
  /// points and normals (in G; normals unnormalized as Open3D's) to the
  /// outputs, units in no particular order.
  void Extract(const open3d::pipelines::integration::ScalableTSDFVolume& volume,
               std::vector<Eigen::Vector3d>* points, std::vector<Eigen::Vector3d>* normals);
  /// Forgets everything (the volume was reset).
  void Clear() { units_.clear(); }

  int units() const { return static_cast<int>(units_.size()); }
  /// Units whose points the last Extract computed anew.
  int units_extracted() const { return units_extracted_; }

 private:
  struct Unit {
    double weight_sum{-1.0};
    bool dirty{true};
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector3d> normals;
  };
  using Key = Eigen::Vector3i;
  struct KeyHash {
    size_t operator()(const Key& k) const;
  };
  std::unordered_map<Key, Unit, KeyHash> units_;
  std::vector<Key> changed_;  // reused between calls
  int units_extracted_{0};
};

}  // namespace graspfill::fusion
