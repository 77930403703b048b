// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/bit_grid.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace graspfill {

void BitGrid::Reset(const Eigen::AlignedBox3f& box, float cell_m, size_t max_cells) {
  if (!(cell_m > 0.0f) || !std::isfinite(cell_m)) {
    throw std::invalid_argument("BitGrid: the cell must be > 0 and finite");
  }
  if (box.isEmpty() || !box.min().allFinite() || !box.max().allFinite()) {
    throw std::invalid_argument("BitGrid: the box is empty or not finite");
  }
  const Eigen::Vector3f extent = box.sizes() / cell_m;
  // Compared in double before any cast: a huge box must not overflow int.
  const double cells = (std::floor(double(extent.x())) + 1) * (std::floor(double(extent.y())) + 1) *
                       (std::floor(double(extent.z())) + 1);
  if (cells > static_cast<double>(max_cells)) {
    throw std::invalid_argument("BitGrid: the box needs more cells than allowed (" +
                                std::to_string(static_cast<long long>(cells)) + " > " +
                                std::to_string(max_cells) + ")");
  }
  origin_ = box.min();
  inv_cell_ = 1.0f / cell_m;
  nx_ = static_cast<int>(extent.x()) + 1;
  ny_ = static_cast<int>(extent.y()) + 1;
  nz_ = static_cast<int>(extent.z()) + 1;
  words_.assign((this->cells() + 63) / 64, 0);  // keeps the capacity
}

bool BitGrid::CellOf(const Eigen::Vector3f& p, int* i, int* j, int* k) const {
  const Eigen::Vector3f c = (p - origin_) * inv_cell_;
  // The negated test also rejects NaN.
  if (!(c.x() >= 0 && c.y() >= 0 && c.z() >= 0 && c.x() < nx_ && c.y() < ny_ && c.z() < nz_)) {
    return false;
  }
  *i = static_cast<int>(c.x());
  *j = static_cast<int>(c.y());
  *k = static_cast<int>(c.z());
  return true;
}

void BitGrid::SetCell(int i, int j, int k) {
  const size_t b = static_cast<size_t>(i) +
                   static_cast<size_t>(nx_) * (static_cast<size_t>(j) + static_cast<size_t>(ny_) * k);
  words_[b >> 6] |= uint64_t{1} << (b & 63);
}

void BitGrid::Set(const Eigen::Vector3f& p, bool dilate) {
  int i, j, k;
  if (!CellOf(p, &i, &j, &k)) return;
  if (!dilate) {
    SetCell(i, j, k);
    return;
  }
  for (int dk = -1; dk <= 1; ++dk) {
    for (int dj = -1; dj <= 1; ++dj) {
      for (int di = -1; di <= 1; ++di) {
        const int a = i + di, b = j + dj, c = k + dk;
        if (a >= 0 && b >= 0 && c >= 0 && a < nx_ && b < ny_ && c < nz_) SetCell(a, b, c);
      }
    }
  }
}

bool BitGrid::Test(const Eigen::Vector3f& p) const {
  int i, j, k;
  if (!CellOf(p, &i, &j, &k)) return false;
  const size_t b = static_cast<size_t>(i) +
                   static_cast<size_t>(nx_) * (static_cast<size_t>(j) + static_cast<size_t>(ny_) * k);
  return (words_[b >> 6] >> (b & 63)) & 1;
}

}  // namespace graspfill
