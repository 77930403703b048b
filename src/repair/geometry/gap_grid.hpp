// SPDX-License-Identifier: BSD-3-Clause
// "Is any point within the gap of q?" for the fills' gap tests (a mirrored
// point next to an original, a claw-hole sample next to the cloud): points
// bucketed on square cells of the gap over two coordinates (u, v) of their
// own (V's x and y, a hole frame's), so that a test looks at 9 cells and
// measures the 3D distance. Exact: the answer does not depend on the cells.
// Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace graspfill::repair::geometry {

class GapGrid {
 public:
  GapGrid() = default;
  /// Cells of `gap_m` from `lo`, enough to hold (u, v) up to `hi`; coarser
  /// where that would be more than kMaxCells (a wide box). No grid (AnyWithin
  /// always false) when the gap is not positive or the box not finite.
  GapGrid(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double gap_m)
      : lo_(lo), r2_(static_cast<float>(gap_m * gap_m)) {
    const Eigen::Vector2d size = hi - lo;
    if (!(gap_m > 0.0) || !size.allFinite() || !(size.minCoeff() >= 0.0)) return;
    cell_ = gap_m;
    while (CellsAlong(size.x()) * CellsAlong(size.y()) > kMaxCells) cell_ *= 2.0;
    nu_ = static_cast<int>(CellsAlong(size.x()));
    nv_ = static_cast<int>(CellsAlong(size.y()));
  }

  bool valid() const { return nu_ > 0; }
  /// The cell size (the gap, or coarser) [m].
  double cell() const { return cell_; }
  /// (u, v) in cells from the grid's corner.
  Eigen::Vector2d InCells(const Eigen::Vector2d& uv) const { return (uv - lo_) / cell_; }
  int cells_u() const { return nu_; }
  int cells_v() const { return nv_; }

  /// A point and its (u, v); points off the grid are left out. Then Build.
  void Add(const Eigen::Vector2d& uv, const Eigen::Vector3f& p) {
    const int c = CellOf(uv);
    if (c >= 0) added_.emplace_back(c, p);
  }
  /// Sorts the points added by cell.
  void Build() {
    if (!valid()) return;
    start_.assign(static_cast<size_t>(nu_) * static_cast<size_t>(nv_) + 1, 0);
    for (const auto& a : added_) ++start_[static_cast<size_t>(a.first) + 1];
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    points_.resize(added_.size());
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (const auto& a : added_)
      points_[static_cast<size_t>(fill[static_cast<size_t>(a.first)]++)] = a.second;
    added_.clear();
    added_.shrink_to_fit();
  }

  /// Whether a point built in lies within the gap of q (3D, in float),
  /// `uv` being q's (u, v).
  bool AnyWithin(const Eigen::Vector2d& uv, const Eigen::Vector3f& q) const {
    if (start_.empty()) return false;
    const Eigen::Vector2d at = InCells(uv);
    if (!at.allFinite()) return false;
    const double iu = std::floor(at.x()), iv = std::floor(at.y());
    const int u0 = static_cast<int>(std::max(0.0, iu - 1.0)), v0 = static_cast<int>(std::max(0.0, iv - 1.0));
    const int u1 = static_cast<int>(std::min(nu_ - 1.0, iu + 1.0)),
              v1 = static_cast<int>(std::min(nv_ - 1.0, iv + 1.0));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const size_t c = static_cast<size_t>(v) * static_cast<size_t>(nu_) + static_cast<size_t>(u);
        for (int k = start_[c]; k < start_[c + 1]; ++k) {
          if ((points_[static_cast<size_t>(k)] - q).squaredNorm() <= r2_) return true;
        }
      }
    }
    return false;
  }

 private:
  static constexpr double kMaxCells = 4e6;
  // Cells from lo up to and including hi's.
  double CellsAlong(double extent) const { return std::floor(extent / cell_) + 1.0; }
  int CellOf(const Eigen::Vector2d& uv) const {
    if (!valid()) return -1;
    const Eigen::Vector2d at = InCells(uv);
    const double iu = std::floor(at.x()), iv = std::floor(at.y());
    if (!(iu >= 0.0 && iu < nu_ && iv >= 0.0 && iv < nv_)) return -1;
    return static_cast<int>(iv) * nu_ + static_cast<int>(iu);
  }

  Eigen::Vector2d lo_{0.0, 0.0};
  float r2_{0.0f};
  double cell_{1.0};
  int nu_{0}, nv_{0};
  std::vector<std::pair<int, Eigen::Vector3f>> added_;
  std::vector<int> start_;  // cell c holds points_[start_[c], start_[c + 1])
  std::vector<Eigen::Vector3f> points_;
};

}  // namespace graspfill::repair::geometry
