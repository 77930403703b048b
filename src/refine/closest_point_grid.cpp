// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/closest_point_grid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace graspfill::refine {

void ClosestPointGrid::Build(const std::vector<Eigen::Vector3f>& points, int stride, double cell_m,
                             double band_m) {
  stride = std::max(1, stride);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  if (box.isEmpty()) {
    Clear();
    return;
  }
  const float cell = static_cast<float>(cell_m);
  const float band = static_cast<float>(band_m);
  cell_ = cell;
  origin_ = box.min().array() - band - cell;
  const Eigen::Vector3f extent = box.max().array() + band + cell - origin_.array();
  nx_ = static_cast<int>(std::ceil(extent.x() / cell));
  ny_ = static_cast<int>(std::ceil(extent.y() / cell));
  nz_ = static_cast<int>(std::ceil(extent.z() / cell));
  const size_t n = static_cast<size_t>(nx_) * ny_ * nz_;
  nearest_.assign(n, -1);
  best_d2_.assign(n, band * band);
  // The cells a point can reach, as offsets from its own cell: the point
  // lies anywhere in that cell, so a cell (di, dj, dl) away is at least
  // max(0, |d| - 0.5) cells away on each axis. Per row (dj, dl) the widest
  // |di| that can still be within the band, -1 for none (a hair of margin
  // for float rounding; the distance test below decides, in the same
  // arithmetic as a scan of every point).
  const int reach = static_cast<int>(std::ceil(band / cell));
  const int side = 2 * reach + 1;
  const double limit = std::pow(band_m / cell_m, 2.0) * (1.0 + 1e-4) + 1e-4;
  const auto gap2 = [](int d) {
    const double g = std::max(0.0, std::abs(d) - 0.5);
    return g * g;
  };
  row_reach_.assign(static_cast<size_t>(side) * side, -1);
  for (int dl = -reach; dl <= reach; ++dl) {
    for (int dj = -reach; dj <= reach; ++dj) {
      int& w = row_reach_[static_cast<size_t>(dj + reach) + static_cast<size_t>(side) * (dl + reach)];
      for (int di = 0; di <= reach && gap2(di) + gap2(dj) + gap2(dl) < limit; ++di) w = di;
    }
  }
  for (size_t k = 0; k < points.size(); k += static_cast<size_t>(stride)) {
    const Eigen::Vector3f& p = points[k];
    const Eigen::Vector3f rel = (p - origin_) / cell;
    const int ci = static_cast<int>(rel.x()), cj = static_cast<int>(rel.y()), ck = static_cast<int>(rel.z());
    const int32_t index = static_cast<int32_t>(k);
    const float origin_x = origin_.x(), p_x = p.x();
    for (int l = std::max(0, ck - reach); l <= std::min(nz_ - 1, ck + reach); ++l) {
      const float dz = origin_.z() + cell * (static_cast<float>(l) + 0.5f) - p.z();
      const float dz2 = dz * dz;
      const int* widths = row_reach_.data() + static_cast<size_t>(side) * (l - ck + reach) + reach - cj;
      for (int j = std::max(0, cj - reach); j <= std::min(ny_ - 1, cj + reach); ++j) {
        const int w = widths[j];
        if (w < 0) continue;
        const float dy = origin_.y() + cell * (static_cast<float>(j) + 0.5f) - p.y();
        const float dy2 = dy * dy;
        const size_t row = static_cast<size_t>(nx_) * (j + static_cast<size_t>(ny_) * l);
        float* const best_d2 = best_d2_.data() + row;
        int32_t* const nearest = nearest_.data() + row;
        const int i_end = std::min(nx_ - 1, ci + w);
        // Both stores unconditional, so that the row vectorizes.
        for (int i = std::max(0, ci - w); i <= i_end; ++i) {
          const float dx = origin_x + cell * (static_cast<float>(i) + 0.5f) - p_x;
          const float d2 = dx * dx + dy2 + dz2;
          const int32_t closer = -static_cast<int32_t>(d2 < best_d2[i]);  // all ones if closer
          nearest[i] = (index & closer) | (nearest[i] & ~closer);
          best_d2[i] = d2 < best_d2[i] ? d2 : best_d2[i];
        }
      }
    }
  }
}

void ClosestPointGrid::Clear() {
  nx_ = ny_ = nz_ = 0;
  nearest_.clear();
}

int ClosestPointGrid::Nearest(const Eigen::Vector3f& p) const {
  const Eigen::Vector3f rel = (p - origin_) / cell_;
  if (!(rel.x() >= 0.0f && rel.y() >= 0.0f && rel.z() >= 0.0f)) return -1;
  const int i = static_cast<int>(rel.x()), j = static_cast<int>(rel.y()), l = static_cast<int>(rel.z());
  if (i >= nx_ || j >= ny_ || l >= nz_) return -1;
  return nearest_[static_cast<size_t>(i) + static_cast<size_t>(nx_) * (j + static_cast<size_t>(ny_) * l)];
}

Eigen::Vector3f ClosestPointGrid::CellCentre(const Eigen::Vector3f& p) const {
  const Eigen::Vector3f rel = (p - origin_) / cell_;
  return origin_ + cell_ * Eigen::Vector3f(std::floor(rel.x()) + 0.5f, std::floor(rel.y()) + 0.5f,
                                           std::floor(rel.z()) + 0.5f);
}

}  // namespace graspfill::refine
