// SPDX-License-Identifier: BSD-3-Clause
#include "triangle_grid.hpp"

#include <algorithm>
#include <cmath>

namespace graspfill::mesh {

TriangleGrid::TriangleGrid(int count, double cell_m)
    : cell_m_(cell_m), filed_(count), boxes_(count), seen_(count, 0) {}

uint64_t TriangleGrid::Key(int x, int y, int z) {
  // 21 bits per axis: a million cells each way, far beyond any mesh here.
  auto bits = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v) & 0x1fffffu); };
  return (bits(x) << 42) | (bits(y) << 21) | bits(z);
}

TriangleGrid::CellRange TriangleGrid::RangeOf(const Eigen::AlignedBox3d& box) const {
  CellRange r;
  for (int k = 0; k < 3; ++k) {
    r.low[k] = static_cast<int>(std::floor(box.min()[k] / cell_m_));
    r.high[k] = static_cast<int>(std::floor(box.max()[k] / cell_m_));
  }
  return r;
}

void TriangleGrid::Remove(int id) {
  const CellRange r = filed_[id];
  for (int x = r.low.x(); x <= r.high.x(); ++x) {
    for (int y = r.low.y(); y <= r.high.y(); ++y) {
      for (int z = r.low.z(); z <= r.high.z(); ++z) {
        std::vector<int>& cell = cells_[Key(x, y, z)];
        cell.erase(std::find(cell.begin(), cell.end(), id));
      }
    }
  }
  filed_[id] = CellRange{};
}

void TriangleGrid::Place(int id, const Eigen::AlignedBox3d& box) {
  Remove(id);
  const CellRange r = RangeOf(box);
  for (int x = r.low.x(); x <= r.high.x(); ++x) {
    for (int y = r.low.y(); y <= r.high.y(); ++y) {
      for (int z = r.low.z(); z <= r.high.z(); ++z) cells_[Key(x, y, z)].push_back(id);
    }
  }
  filed_[id] = r;
  boxes_[id] = box;
}

void TriangleGrid::Near(const Eigen::AlignedBox3d& box, std::vector<int>* out) {
  out->clear();
  if (++query_ == 0) {  // the stamp wrapped: forget every old one
    std::fill(seen_.begin(), seen_.end(), 0);
    query_ = 1;
  }
  const CellRange r = RangeOf(box);
  for (int x = r.low.x(); x <= r.high.x(); ++x) {
    for (int y = r.low.y(); y <= r.high.y(); ++y) {
      for (int z = r.low.z(); z <= r.high.z(); ++z) {
        const auto it = cells_.find(Key(x, y, z));
        if (it == cells_.end()) continue;
        for (int id : it->second) {
          if (seen_[id] == query_) continue;
          seen_[id] = query_;
          if (boxes_[id].intersects(box)) out->push_back(id);
        }
      }
    }
  }
}

}  // namespace graspfill::mesh
