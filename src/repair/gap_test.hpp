// SPDX-License-Identifier: BSD-3-Clause
// The gap test of the claw-hole fill: a sample is new only where neither
// the cloud nor an earlier hole's fill has a point within the gap. Internal
// to the repair library.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "clamped_int.hpp"
#include "geometry/gap_grid.hpp"
#include "hole_fill.hpp"

namespace graspfill::repair::fill {

// Samples already added, hashed on a grid, so that holes whose boxes
// overlap do not fill the same place twice.
class AddedPoints {
 public:
  explicit AddedPoints(double cell_m) : cell_(cell_m) {}
  bool AnyWithin(const Eigen::Vector3f& p, double radius_m) const {
    const int reach = static_cast<int>(std::ceil(radius_m / cell_));
    const Eigen::Vector3i c = Cell(p);
    const float r2 = static_cast<float>(radius_m * radius_m);
    for (int dx = -reach; dx <= reach; ++dx) {
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dz = -reach; dz <= reach; ++dz) {
          const auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const Eigen::Vector3f& q : it->second) {
            if ((q - p).squaredNorm() <= r2) return true;
          }
        }
      }
    }
    return false;
  }
  void Add(const Eigen::Vector3f& p) { cells_[Key(Cell(p))].push_back(p); }

 private:
  // Clamped into int's range: a cloud far from the origin must not
  // overflow the cast (its cells then share keys, which only costs time).
  Eigen::Vector3i Cell(const Eigen::Vector3f& p) const {
    const auto index = [this](float v) { return FloorToInt(v / cell_, -1000000000, 1000000000); };
    return Eigen::Vector3i(index(p.x()), index(p.y()), index(p.z()));
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<uint64_t>(v) & 0x1fffffULL; };
    return (u(c.x()) << 42) | (u(c.y()) << 21) | u(c.z());
  }
  double cell_;
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3f>> cells_;
};

// Decides whether a candidate is new: no cloud point and no point added
// for an earlier hole within `gap_m`. Samples of the same surface are not
// tested against each other: that would thin the fill below the input's
// density (half the points of a random sampling have a neighbour closer
// than D). For a hole, the points that can be that close (the cloud points
// of the support box and the earlier fills) are bucketed on a 2D grid over
// the hole's (u, v) rectangle, so that a test is nine cell lookups instead
// of a KD-tree query (which took about half of the fill's time); a
// candidate off the grid asks the shared index and the earlier fills.
class GapTest {
 public:
  GapTest(const NeighborIndex& index, const AddedPoints* earlier, double gap_m)
      : index_(index), earlier_(earlier), gap_m_(gap_m) {}

  // Grid over (u, v) in [lo, hi] of `frame`: `near` (indices into the
  // cloud) must hold every cloud point of `covered`.
  void BuildGrid(const HoleFrame& frame, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                 const std::vector<int>& near, const Box& covered, const PointList& earlier_fill);
  bool IsNew(const Eigen::Vector3f& p);

 private:
  const NeighborIndex& index_;
  const AddedPoints* earlier_;
  double gap_m_;
  std::vector<int> nn_;
  std::vector<double> d2_;
  // The grid (none when frame_ is null).
  const HoleFrame* frame_{nullptr};
  Box trusted_;  // candidates inside it are decided by the grid alone
  geometry::GapGrid grid_;
};

}  // namespace graspfill::repair::fill
