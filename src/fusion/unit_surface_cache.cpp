// SPDX-License-Identifier: BSD-3-Clause
#include "unit_surface_cache.hpp"

#include <open3d/pipelines/integration/UniformTSDFVolume.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace graspfill::fusion {
namespace {

using Volume = open3d::pipelines::integration::ScalableTSDFVolume;
using UnitVolume = open3d::pipelines::integration::UniformTSDFVolume;

// The eight corners of a voxel cell, in the order of the trilinear formula
// below (Open3D's marching-cubes corner order).
const Eigen::Vector3i kCorner[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

// Open3D stores only blocks fused into; a crossing is only where both ends
// are fused and within the truncation band (|tsdf| < 0.98).
bool NearSurface(float weight, float tsdf) { return weight != 0.0f && tsdf < 0.98f && tsdf >= -0.98f; }

const UnitVolume* FindUnit(const Volume& volume, const Eigen::Vector3i& key) {
  const auto it = volume.volume_units_.find(key);
  return it == volume.volume_units_.end() ? nullptr : it->second.volume_.get();
}

// The units a unit's extraction reads: itself and its 26 neighbours, looked
// up once (the normals' samples read up to two voxels across a face).
class Neighbourhood {
 public:
  Neighbourhood(const Volume& volume, const Eigen::Vector3i& centre) : volume_(volume), centre_(centre) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          units_[Slot(dx, dy, dz)] = FindUnit(volume, centre + Eigen::Vector3i(dx, dy, dz));
        }
      }
    }
  }
  // A unit's extraction reaches only keys within one unit of it; any other
  // is looked up.
  const UnitVolume* operator()(const Eigen::Vector3i& key) const {
    const Eigen::Vector3i d = key - centre_;
    if (d.cwiseAbs().maxCoeff() > 1) return FindUnit(volume_, key);
    return units_[Slot(d.x(), d.y(), d.z())];
  }

 private:
  static int Slot(int dx, int dy, int dz) { return (dx + 1) * 9 + (dy + 1) * 3 + (dz + 1); }
  const Volume& volume_;
  Eigen::Vector3i centre_;
  const UnitVolume* units_[27];
};

// The TSDF at p, trilinear over the eight voxel centres around it (0 where
// a unit is missing), with the same terms in the same order as Open3D's
// ScalableTSDFVolume::GetTSDFAt, so the normals come out bit for bit.
double TsdfAt(const Volume& volume, const Neighbourhood& near, const Eigen::Vector3d& p) {
  const double voxel = volume.voxel_length_;
  const int res = volume.volume_unit_resolution_;
  const Eigen::Vector3d p_locate = p - Eigen::Vector3d(0.5, 0.5, 0.5) * voxel;
  const Eigen::Vector3i unit(static_cast<int>(std::floor(p_locate(0) / volume.volume_unit_length_)),
                             static_cast<int>(std::floor(p_locate(1) / volume.volume_unit_length_)),
                             static_cast<int>(std::floor(p_locate(2) / volume.volume_unit_length_)));
  const UnitVolume* u0 = near(unit);
  if (u0 == nullptr) return 0.0;
  const Eigen::Vector3d p_grid = (p_locate - unit.cast<double>() * volume.volume_unit_length_) / voxel;
  Eigen::Vector3i idx0;
  for (int i = 0; i < 3; ++i) idx0(i) = std::clamp(static_cast<int>(std::floor(p_grid(i))), 0, res - 1);
  const Eigen::Vector3d r = p_grid - idx0.cast<double>();
  float f[8];
  for (int c = 0; c < 8; ++c) {
    Eigen::Vector3i idx1 = idx0 + kCorner[c];
    Eigen::Vector3i unit1 = unit;
    const UnitVolume* u = u0;
    if (idx1(0) >= res || idx1(1) >= res || idx1(2) >= res) {
      for (int j = 0; j < 3; ++j) {
        if (idx1(j) >= res) idx1(j) -= res, unit1(j) += 1;
      }
      u = near(unit1);
    }
    f[c] = u == nullptr ? 0.0f : u->voxels_[u->IndexOf(idx1)].tsdf_;
  }
  return (1 - r(0)) *
             ((1 - r(1)) * ((1 - r(2)) * f[0] + r(2) * f[4]) + r(1) * ((1 - r(2)) * f[3] + r(2) * f[7])) +
         r(0) * ((1 - r(1)) * ((1 - r(2)) * f[1] + r(2) * f[5]) + r(1) * ((1 - r(2)) * f[2] + r(2) * f[6]));
}

// Central differences 0.99 voxel either side (Open3D's GetNormalAt).
Eigen::Vector3d NormalAt(const Volume& volume, const Neighbourhood& near, const Eigen::Vector3d& p) {
  const double half_gap = 0.99 * volume.voxel_length_;
  Eigen::Vector3d n;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d p0 = p, p1 = p;
    p0(i) -= half_gap;
    p1(i) += half_gap;
    n(i) = TsdfAt(volume, near, p1) - TsdfAt(volume, near, p0);
  }
  return n.normalized();
}

// The zero crossings on the edges from each of the unit's voxels to its +x,
// +y and +z neighbours (Open3D's ExtractPointCloud for one unit).
void ExtractUnit(const Volume& volume, const Eigen::Vector3i& unit, const UnitVolume& v0,
                 std::vector<Eigen::Vector3d>* points, std::vector<Eigen::Vector3d>* normals) {
  const double voxel = volume.voxel_length_;
  const double half_voxel = voxel * 0.5;
  const int res = v0.resolution_;
  const Neighbourhood near(volume, unit);
  const UnitVolume* next[3];
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3i key = unit;
    key(i) += 1;
    next[i] = near(key);
  }
  for (int x = 0; x < res; ++x) {
    for (int y = 0; y < res; ++y) {
      for (int z = 0; z < res; ++z) {
        const Eigen::Vector3i idx0(x, y, z);
        const auto& voxel0 = v0.voxels_[v0.IndexOf(idx0)];
        const float f0 = voxel0.tsdf_;
        if (!NearSurface(voxel0.weight_, f0)) continue;
        const Eigen::Vector3d p0 =
            Eigen::Vector3d(half_voxel + voxel * x, half_voxel + voxel * y, half_voxel + voxel * z) +
            unit.cast<double>() * volume.volume_unit_length_;
        for (int i = 0; i < 3; ++i) {
          Eigen::Vector3d p1 = p0;
          Eigen::Vector3i idx1 = idx0;
          p1(i) += voxel;
          idx1(i) += 1;
          const UnitVolume* v1 = &v0;
          if (idx1(i) >= res) idx1(i) -= res, v1 = next[i];
          const float w1 = v1 == nullptr ? 0.0f : v1->voxels_[v1->IndexOf(idx1)].weight_;
          const float f1 = v1 == nullptr ? 0.0f : v1->voxels_[v1->IndexOf(idx1)].tsdf_;
          if (!NearSurface(w1, f1) || !(f0 * f1 < 0)) continue;
          const float r0 = std::fabs(f0);
          const float r1 = std::fabs(f1);
          Eigen::Vector3d p = p0;
          p(i) = (p0(i) * r1 + p1(i) * r0) / (r0 + r1);
          points->push_back(p);
          normals->push_back(NormalAt(volume, near, p));
        }
      }
    }
  }
}

double WeightSum(const UnitVolume& v) {
  double sum = 0.0;
  for (const auto& voxel : v.voxels_) sum += voxel.weight_;
  return sum;
}

}  // namespace

size_t UnitSurfaceCache::KeyHash::operator()(const Key& k) const {
  size_t h = std::hash<int>()(k.x());
  h = h * 1000003u ^ std::hash<int>()(k.y());
  return h * 1000003u ^ std::hash<int>()(k.z());
}

void UnitSurfaceCache::Extract(const Volume& volume, std::vector<Eigen::Vector3d>* points,
                               std::vector<Eigen::Vector3d>* normals) {
  // Units only go away with a reset of the volume: start over then.
  if (units_.size() > volume.volume_units_.size()) units_.clear();
  changed_.clear();
  for (const auto& [key, unit] : volume.volume_units_) {
    if (!unit.volume_) continue;
    const double sum = WeightSum(*unit.volume_);
    auto [it, added] = units_.try_emplace(key);
    if (added || it->second.weight_sum != sum) {
      it->second.weight_sum = sum;
      changed_.push_back(key);
    }
  }
  for (const Key& key : changed_) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = units_.find(key + Key(dx, dy, dz));
          if (it != units_.end()) it->second.dirty = true;
        }
      }
    }
  }
  units_extracted_ = 0;
  for (auto& [key, unit] : units_) {
    if (unit.dirty) {
      unit.points.clear();
      unit.normals.clear();
      if (const UnitVolume* v = FindUnit(volume, key))
        ExtractUnit(volume, key, *v, &unit.points, &unit.normals);
      unit.dirty = false;
      ++units_extracted_;
    }
    points->insert(points->end(), unit.points.begin(), unit.points.end());
    normals->insert(normals->end(), unit.normals.begin(), unit.normals.end());
  }
}

}  // namespace graspfill::fusion
