// SPDX-License-Identifier: BSD-3-Clause
// A cloud cut into horizontal slabs (along V's z) and the 2D convex outline
// of the points around any height: the symmetry step compares these
// outlines, the claw-hole step keeps its fills out of them. Internal to
// src/repair.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "clamped_int.hpp"
#include "geometry/polygon_2d.hpp"
#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Most slabs a profile of the repair is cut into: 20 m of 1 mm slabs, past
/// any object the repair takes (its extent is at most kMaxRepairExtentM);
/// a stray point far from the object stretches no profile beyond it.
constexpr int kMaxProfileSlabs = 20000;

/// `count` slabs of thickness h from z0 up; points outside them are left out.
class SlabProfile {
 public:
  /// `points` are kept by reference: they must outlive the profile.
  SlabProfile(const PointList& points, double z0, double h, int count)
      : points_(points), z0_(z0), h_(h), slabs_(static_cast<size_t>(std::max(count, 0))) {
    for (size_t i = 0; i < points.size(); ++i) {
      const double k = std::floor((points[i].z() - z0) / h);
      if (k >= 0.0 && k < count) slabs_[static_cast<size_t>(k)].push_back(static_cast<int>(i));
    }
  }
  int count() const { return static_cast<int>(slabs_.size()); }
  /// The indices (into the points) of slab k's points.
  const std::vector<int>& Indices(int k) const { return slabs_[static_cast<size_t>(k)]; }
  double Centre(int k) const { return z0_ + (k + 0.5) * h_; }
  /// The slab holding height z, or -1 outside them all.
  int SlabOf(double z) const {
    const double k = std::floor((z - z0_) / h_);
    return k >= 0.0 && k < count() ? static_cast<int>(k) : -1;
  }

  /// Counter-clockwise convex hull (xOy) of the points with |z - zc| < h / 2;
  /// empty when fewer than `min_points` fall there or they span no area.
  std::vector<Eigen::Vector2d> HullAt(double zc, int min_points) const {
    const int k0 = FloorToInt((zc - 0.5 * h_ - z0_) / h_, 0, count());
    const int k1 = FloorToInt((zc + 0.5 * h_ - z0_) / h_, -1, count() - 1);
    std::vector<Eigen::Vector2d> pts;
    for (int k = k0; k <= k1; ++k) {
      for (int i : slabs_[static_cast<size_t>(k)]) {
        const Eigen::Vector3f& p = points_[static_cast<size_t>(i)];
        if (std::abs(p.z() - zc) < 0.5 * h_) pts.emplace_back(p.x(), p.y());
      }
    }
    if (static_cast<int>(pts.size()) < min_points) return {};
    // A thin-walled slab has all its points on the hull; 512 of them place
    // its outline to ~r (1 - cos(pi / 512)), far below the sampling noise.
    if (pts.size() > 1024) {
      const size_t stride = pts.size() / 512;
      size_t m = 0;
      for (size_t i = 0; i < pts.size(); i += stride) pts[m++] = pts[i];
      pts.resize(m);
    }
    std::vector<Eigen::Vector2d> hull = geometry::ConvexHull2d(&pts);
    if (hull.size() < 3) hull.clear();
    return hull;
  }
  std::vector<Eigen::Vector2d> Hull(int k, int min_points) const { return HullAt(Centre(k), min_points); }

 private:
  const PointList& points_;
  double z0_, h_;
  std::vector<std::vector<int>> slabs_;
};

}  // namespace graspfill::repair
