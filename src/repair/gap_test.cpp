#include "gap_test.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace graspfill::repair::fill {

void GapTest::BuildGrid(const HoleFrame& frame, const Eigen::Vector2d& lo,
                        const Eigen::Vector2d& hi, const std::vector<int>& near,
                        const Box& covered, const PointList& earlier_fill) {
  frame_ = nullptr;
  if (!(gap_m_ > 0.0)) return;
  cell_ = gap_m_;
  lo_ = lo - Eigen::Vector2d::Constant(cell_);
  const Eigen::Vector2d size = hi - lo_ + Eigen::Vector2d::Constant(cell_);
  const double cells = std::ceil(size.x() / cell_) * std::ceil(size.y() / cell_);
  if (!(cells > 0.0) || cells > 4e6) return;  // a degenerate rim: no grid
  nu_ = static_cast<int>(std::ceil(size.x() / cell_));
  nv_ = static_cast<int>(std::ceil(size.y() / cell_));
  const PointList& cloud = index_.points();
  std::vector<std::pair<int, Eigen::Vector3f>> binned;
  const auto bin = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector3d l = frame.Local(p.cast<double>());
    const int iu = static_cast<int>(std::floor((l.x() - lo_.x()) / cell_));
    const int iv = static_cast<int>(std::floor((l.y() - lo_.y()) / cell_));
    if (iu >= 0 && iu < nu_ && iv >= 0 && iv < nv_) binned.emplace_back(iv * nu_ + iu, p);
  };
  for (int i : near) bin(cloud[i]);
  for (const Eigen::Vector3f& p : earlier_fill) bin(p);
  start_.assign(static_cast<size_t>(nu_) * nv_ + 1, 0);
  for (const auto& b : binned) ++start_[b.first + 1];
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  pts_.resize(binned.size());
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (const auto& b : binned) pts_[fill[b.first]++] = b.second;
  const Eigen::Vector3f g = Eigen::Vector3f::Constant(static_cast<float>(gap_m_));
  trusted_ = Box(covered.min() + g, covered.max() - g);
  frame_ = &frame;
}

bool GapTest::GridHas(const Eigen::Vector3f& p, const Eigen::Vector3d& local) const {
  const int iu = static_cast<int>(std::floor((local.x() - lo_.x()) / cell_));
  const int iv = static_cast<int>(std::floor((local.y() - lo_.y()) / cell_));
  const float r2 = static_cast<float>(gap_m_ * gap_m_);
  for (int v = std::max(0, iv - 1); v <= std::min(nv_ - 1, iv + 1); ++v) {
    for (int u = std::max(0, iu - 1); u <= std::min(nu_ - 1, iu + 1); ++u) {
      const int c = v * nu_ + u;
      for (int k = start_[c]; k < start_[c + 1]; ++k) {
        if ((pts_[k] - p).squaredNorm() <= r2) return true;
      }
    }
  }
  return false;
}

bool GapTest::IsNew(const Eigen::Vector3f& p) {
  if (!(gap_m_ > 0.0)) return true;
  if (frame_ != nullptr && trusted_.contains(p)) {
    const Eigen::Vector3d l = frame_->Local(p.cast<double>());
    const double iu = (l.x() - lo_.x()) / cell_, iv = (l.y() - lo_.y()) / cell_;
    if (iu >= 1.0 && iu < nu_ - 1.0 && iv >= 1.0 && iv < nv_ - 1.0) return !GridHas(p, l);
  }
  index_.Knn(p, 1, &nn_, &d2_);
  if (!d2_.empty() && d2_[0] <= gap_m_ * gap_m_) return false;
  return earlier_ == nullptr || !earlier_->AnyWithin(p, gap_m_);
}

}  // namespace graspfill::repair::fill
