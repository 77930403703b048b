#include "graspfill/refine/closest_point_grid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace graspfill::refine {

void ClosestPointGrid::Build(const std::vector<Eigen::Vector3f>& points, int stride,
                             double cell_m, double band_m) {
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
  const int reach = static_cast<int>(std::ceil(band / cell));
  for (size_t k = 0; k < points.size(); k += static_cast<size_t>(stride)) {
    const Eigen::Vector3f rel = (points[k] - origin_) / cell;
    const int ci = static_cast<int>(rel.x()), cj = static_cast<int>(rel.y()),
              ck = static_cast<int>(rel.z());
    for (int l = std::max(0, ck - reach); l <= std::min(nz_ - 1, ck + reach); ++l) {
      for (int j = std::max(0, cj - reach); j <= std::min(ny_ - 1, cj + reach); ++j) {
        for (int i = std::max(0, ci - reach); i <= std::min(nx_ - 1, ci + reach); ++i) {
          const Eigen::Vector3f centre = origin_ + cell * Eigen::Vector3f(i + 0.5f, j + 0.5f, l + 0.5f);
          const float d2 = (centre - points[k]).squaredNorm();
          const size_t c = static_cast<size_t>(i) + static_cast<size_t>(nx_) * (j + static_cast<size_t>(ny_) * l);
          if (d2 < best_d2_[c]) {
            best_d2_[c] = d2;
            nearest_[c] = static_cast<int32_t>(k);
          }
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

}  // namespace graspfill::refine
