// SPDX-License-Identifier: BSD-3-Clause
#include "gap_test.hpp"

#include <algorithm>
#include <cmath>

namespace graspfill::repair::fill {

void GapTest::BuildGrid(const HoleFrame& frame, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                        const std::vector<int>& near, const Box& covered, const PointList& earlier_fill) {
  frame_ = nullptr;
  const Eigen::Vector2d pad = Eigen::Vector2d::Constant(gap_m_);
  grid_ = geometry::GapGrid(lo - pad, hi + pad, gap_m_);
  if (!grid_.valid()) return;  // a degenerate rim: no grid
  const auto add = [&](const Eigen::Vector3f& p) { grid_.Add(frame.Local(p.cast<double>()).head<2>(), p); };
  for (int i : near) add(index_.points()[i]);
  for (const Eigen::Vector3f& p : earlier_fill) add(p);
  grid_.Build();
  const Eigen::Vector3f g = Eigen::Vector3f::Constant(static_cast<float>(gap_m_));
  trusted_ = Box(covered.min() + g, covered.max() - g);
  frame_ = &frame;
}

bool GapTest::IsNew(const Eigen::Vector3f& p) {
  if (!(gap_m_ > 0.0)) return true;
  if (frame_ != nullptr && trusted_.contains(p)) {
    // Off the grid's outer ring of cells, the grid holds every point that
    // can be within the gap.
    const Eigen::Vector2d uv = frame_->Local(p.cast<double>()).head<2>();
    const Eigen::Vector2d at = grid_.InCells(uv);
    if (at.x() >= 1.0 && at.x() < grid_.cells_u() - 1.0 && at.y() >= 1.0 && at.y() < grid_.cells_v() - 1.0) {
      return !grid_.AnyWithin(uv, p);
    }
  }
  index_.Knn(p, 1, &nn_, &d2_);
  if (!d2_.empty() && d2_[0] <= gap_m_ * gap_m_) return false;
  return earlier_ == nullptr || !earlier_->AnyWithin(p, gap_m_);
}

}  // namespace graspfill::repair::fill
