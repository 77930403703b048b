#include "graspfill/repair/neighbor_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace graspfill::repair {
namespace {

// (squared distance, index): sorted by distance, ties by index, so that
// every query has one deterministic answer.
using Candidate = std::pair<double, int>;

// Per-thread scratch: a query allocates nothing once it has grown.
std::vector<Candidate>& Scratch() {
  thread_local std::vector<Candidate> candidates;
  return candidates;
}

}  // namespace

struct NeighborIndex::Impl {
  Eigen::Vector3f origin{0, 0, 0};
  float cell{1.0f};
  int n[3]{1, 1, 1};
  std::vector<int> cell_start;  // cells + 1 offsets into `order`/`sorted`
  std::vector<int> order;       // point indices, grouped by cell
  PointList sorted;             // the points in that order

  // Grid over `points` with cubic cells of `cell` [m] (coarsened until the
  // grid has at most ~4 cells per point), points counting-sorted by cell.
  void Build(const PointList& points, double cell);

  int CellOf(float x, int axis) const {
    const int i = static_cast<int>(std::floor((x - origin[axis]) / cell));
    return std::clamp(i, 0, n[axis] - 1);
  }
  int Flat(int x, int y, int z) const { return (z * n[1] + y) * n[0] + x; }

  // Adds the points of cell (x, y, z) to `out`.
  void Collect(int x, int y, int z, const Eigen::Vector3d& q, std::vector<Candidate>* out) const {
    const int c = Flat(x, y, z);
    for (int j = cell_start[c]; j < cell_start[c + 1]; ++j) {
      out->emplace_back((sorted[j].cast<double>() - q).squaredNorm(), order[j]);
    }
  }

  // Adds the cells at Chebyshev distance exactly `r` from `centre`.
  void CollectShell(const int centre[3], int r, const Eigen::Vector3d& q,
                    std::vector<Candidate>* out) const {
    const int z0 = std::max(0, centre[2] - r), z1 = std::min(n[2] - 1, centre[2] + r);
    const int y0 = std::max(0, centre[1] - r), y1 = std::min(n[1] - 1, centre[1] + r);
    const int x0 = std::max(0, centre[0] - r), x1 = std::min(n[0] - 1, centre[0] + r);
    for (int z = z0; z <= z1; ++z) {
      for (int y = y0; y <= y1; ++y) {
        if (std::abs(z - centre[2]) == r || std::abs(y - centre[1]) == r) {
          for (int x = x0; x <= x1; ++x) Collect(x, y, z, q, out);
        } else {  // inside the shell's slab only its two x faces are new
          if (centre[0] - r >= 0) Collect(centre[0] - r, y, z, q, out);
          if (centre[0] + r < n[0]) Collect(centre[0] + r, y, z, q, out);
        }
      }
    }
  }

  // Distance from q to the nearest cell outside the block of half-width r
  // (infinite when the block covers the grid).
  double Unsearched(const int centre[3], int r, const Eigen::Vector3d& q) const {
    double bound = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (centre[a] - r > 0) {
        bound = std::min(bound, q[a] - (origin[a] + static_cast<double>(centre[a] - r) * cell));
      }
      if (centre[a] + r + 1 < n[a]) {
        bound = std::min(bound, origin[a] + static_cast<double>(centre[a] + r + 1) * cell - q[a]);
      }
    }
    return bound;
  }
};

NeighborIndex::NeighborIndex(const PointList& points)
    : points_(points), impl_(std::make_unique<Impl>()) {
  if (points.empty()) throw std::invalid_argument("NeighborIndex: empty cloud");
  // First about one cell per point over the bounding box; then cells of
  // ~1.25x the typical distance to the 20th neighbour, measured on a few
  // hundred points: the 27 cells around a point then hold its 20 nearest
  // with few others (on a rotated surface sample the first grid has cells
  // ~2x larger and ~2x the candidates).
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const Eigen::Vector3f extent = box.sizes().cwiseMax(1e-6f);
  const double count = static_cast<double>(points.size());
  impl_->Build(points, std::cbrt(static_cast<double>(extent.x()) * extent.y() * extent.z() / count));
  constexpr int kTypicalK = 21;
  if (points.size() > 4 * kTypicalK) {
    std::vector<int> nn;
    std::vector<double> d2;
    std::vector<double> radius;
    const size_t stride = std::max<size_t>(1, points.size() / 256);
    for (size_t i = 0; i < points.size(); i += stride) {
      Knn(points[i], kTypicalK, &nn, &d2);
      radius.push_back(std::sqrt(d2.back()));
    }
    std::nth_element(radius.begin(), radius.begin() + static_cast<long>(radius.size() / 2),
                     radius.end());
    const double cell = 1.25 * radius[radius.size() / 2];
    if (cell > 0.0 && cell < impl_->cell) impl_->Build(points, cell);
  }
}

void NeighborIndex::Impl::Build(const PointList& points, double cell) {
  Impl& g = *this;
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const Eigen::Vector3f extent = box.sizes().cwiseMax(1e-6f);
  const double count = static_cast<double>(points.size());
  cell = std::max(cell, 1e-7);
  auto cells = [&](double c) {
    double total = 1.0;
    for (int a = 0; a < 3; ++a) total *= std::floor(extent[a] / c) + 1.0;
    return total;
  };
  while (cells(cell) > 4.0 * count + 64.0) cell *= 1.25;
  g.cell = static_cast<float>(cell);
  g.origin = box.min();
  for (int a = 0; a < 3; ++a) g.n[a] = static_cast<int>(std::floor(extent[a] / cell)) + 1;

  // Counting sort of the points by cell.
  const size_t num_cells = static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2];
  std::vector<int> cell_of(points.size());
  g.cell_start.assign(num_cells + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    cell_of[i] = g.Flat(g.CellOf(p.x(), 0), g.CellOf(p.y(), 1), g.CellOf(p.z(), 2));
    ++g.cell_start[static_cast<size_t>(cell_of[i]) + 1];
  }
  for (size_t c = 0; c < num_cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  std::vector<int> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  g.order.resize(points.size());
  g.sorted.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const int slot = fill[static_cast<size_t>(cell_of[i])]++;
    g.order[slot] = static_cast<int>(i);
    g.sorted[slot] = points[i];
  }
}

NeighborIndex::~NeighborIndex() = default;

void NeighborIndex::Knn(const Eigen::Vector3f& query, int k, std::vector<int>* indices,
                        std::vector<double>* squared_distances) const {
  const Impl& g = *impl_;
  indices->clear();
  if (squared_distances) squared_distances->clear();
  if (k <= 0) return;
  size_t want = std::min(static_cast<size_t>(k), points_.size());
  const Eigen::Vector3d q = query.cast<double>();
  const int centre[3] = {g.CellOf(query.x(), 0), g.CellOf(query.y(), 1), g.CellOf(query.z(), 2)};
  std::vector<Candidate>& found = Scratch();
  found.clear();
  g.Collect(centre[0], centre[1], centre[2], q, &found);
  // Grow the block shell by shell until the k-th nearest found so far is
  // nearer than anything outside it.
  for (int r = 1;; ++r) {
    g.CollectShell(centre, r, q, &found);
    const double bound = g.Unsearched(centre, r, q);
    if (found.size() < want) {
      if (std::isinf(bound)) break;  // cannot happen: want <= size
      continue;
    }
    std::nth_element(found.begin(), found.begin() + static_cast<long>(want - 1), found.end());
    if (std::isinf(bound) || found[want - 1].first <= bound * bound) break;
  }
  want = std::min(want, found.size());
  std::partial_sort(found.begin(), found.begin() + static_cast<long>(want), found.end());
  for (size_t j = 0; j < want; ++j) {
    indices->push_back(found[j].second);
    if (squared_distances) squared_distances->push_back(found[j].first);
  }
}

KnnTable NeighborIndex::AllKnn(int k) const {
  const Impl& g = *impl_;
  KnnTable table;
  table.k = std::max(0, std::min(k, static_cast<int>(points_.size())));
  if (table.k == 0) return table;
  const size_t want = static_cast<size_t>(table.k);
  table.indices.resize(points_.size() * want);
  table.squared_distances.resize(points_.size() * want);
  // The candidates of one cell (its 3 x 3 x 3 block) as float columns, so
  // that the distances of a query to all of them vectorize; the few that
  // can be among the k nearest are then ranked exactly, in double.
  std::vector<float> cx, cy, cz, dist, scratch;
  std::vector<int> cid;
  std::vector<Candidate> exact;
  std::vector<int> fallback_nn;
  std::vector<double> fallback_d2;
  for (int z = 0; z < g.n[2]; ++z) {
    for (int y = 0; y < g.n[1]; ++y) {
      for (int x = 0; x < g.n[0]; ++x) {
        const int c = g.Flat(x, y, z);
        if (g.cell_start[c] == g.cell_start[c + 1]) continue;
        cx.clear(), cy.clear(), cz.clear(), cid.clear();
        const int x0 = std::max(0, x - 1), x1 = std::min(g.n[0] - 1, x + 1);
        for (int bz = std::max(0, z - 1); bz <= std::min(g.n[2] - 1, z + 1); ++bz) {
          for (int by = std::max(0, y - 1); by <= std::min(g.n[1] - 1, y + 1); ++by) {
            // Three cells along x are contiguous in `sorted`.
            for (int m = g.cell_start[g.Flat(x0, by, bz)]; m < g.cell_start[g.Flat(x1, by, bz) + 1]; ++m) {
              cx.push_back(g.sorted[m].x());
              cy.push_back(g.sorted[m].y());
              cz.push_back(g.sorted[m].z());
              cid.push_back(m);
            }
          }
        }
        const size_t num = cid.size();
        dist.resize(num);
        const int centre[3] = {x, y, z};
        for (int j = g.cell_start[c]; j < g.cell_start[c + 1]; ++j) {
          const Eigen::Vector3f& qf = g.sorted[j];
          const int point = g.order[j];
          int* row = table.indices.data() + static_cast<size_t>(point) * want;
          double* row_d2 = table.squared_distances.data() + static_cast<size_t>(point) * want;
          for (size_t m = 0; m < num; ++m) {
            const float dx = cx[m] - qf.x(), dy = cy[m] - qf.y(), dz = cz[m] - qf.z();
            dist[m] = dx * dx + dy * dy + dz * dz;
          }
          // The k-th smallest float distance, with a margin for rounding.
          float kth = std::numeric_limits<float>::infinity();
          if (num >= want) {
            scratch.assign(dist.begin(), dist.end());
            std::nth_element(scratch.begin(), scratch.begin() + static_cast<long>(want - 1), scratch.end());
            kth = scratch[want - 1] * (1.0f + 1e-5f) + 1e-30f;
          }
          // Exact only if nothing outside the block can be nearer.
          const Eigen::Vector3d q = qf.cast<double>();
          const double bound = g.Unsearched(centre, 1, q);
          if (!(std::isinf(bound) ? num >= want : kth < 0.999 * bound * bound)) {
            Knn(points_[static_cast<size_t>(point)], table.k, &fallback_nn, &fallback_d2);
            std::copy(fallback_nn.begin(), fallback_nn.end(), row);
            std::copy(fallback_d2.begin(), fallback_d2.end(), row_d2);
            continue;
          }
          exact.clear();
          for (size_t m = 0; m < num; ++m) {
            if (dist[m] <= kth) {
              const int slot = cid[m];
              exact.emplace_back((g.sorted[slot].cast<double>() - q).squaredNorm(), g.order[slot]);
            }
          }
          std::sort(exact.begin(), exact.end());  // ~k of them: insertion sort
          for (size_t m = 0; m < want; ++m) {
            row[m] = exact[m].second;
            row_d2[m] = exact[m].first;
          }
        }
      }
    }
  }
  return table;
}

void NeighborIndex::Radius(const Eigen::Vector3f& query, double radius_m,
                           std::vector<int>* indices,
                           std::vector<double>* squared_distances) const {
  const Impl& g = *impl_;
  indices->clear();
  if (squared_distances) squared_distances->clear();
  if (!(radius_m >= 0.0)) return;
  const Eigen::Vector3d q = query.cast<double>();
  const int centre[3] = {g.CellOf(query.x(), 0), g.CellOf(query.y(), 1), g.CellOf(query.z(), 2)};
  std::vector<Candidate>& found = Scratch();
  found.clear();
  g.Collect(centre[0], centre[1], centre[2], q, &found);
  for (int r = 1; g.Unsearched(centre, r - 1, q) <= radius_m; ++r) {
    g.CollectShell(centre, r, q, &found);
  }
  const double r2 = radius_m * radius_m;
  found.erase(std::remove_if(found.begin(), found.end(),
                             [r2](const Candidate& c) { return c.first > r2; }),
              found.end());
  std::sort(found.begin(), found.end());
  for (const Candidate& c : found) {
    indices->push_back(c.second);
    if (squared_distances) squared_distances->push_back(c.first);
  }
}

KnnTable RestrictTable(const KnnTable& table, const std::vector<int>& kept,
                       const NeighborIndex& kept_index) {
  if (kept.size() != kept_index.size()) {
    throw std::invalid_argument("RestrictTable: the index is not over the kept points");
  }
  std::vector<int> renumber(table.size(), -1);
  for (size_t i = 0; i < kept.size(); ++i) renumber.at(static_cast<size_t>(kept[i])) = static_cast<int>(i);
  KnnTable out;
  out.k = std::min(table.k, static_cast<int>(kept.size()));
  const size_t k = static_cast<size_t>(out.k);
  out.indices.resize(kept.size() * k);
  out.squared_distances.resize(kept.size() * k);
  std::vector<int> nn;
  std::vector<double> d2;
  for (size_t i = 0; i < kept.size(); ++i) {
    const size_t old_row = static_cast<size_t>(kept[i]);
    int* row = out.indices.data() + i * k;
    double* row_d2 = out.squared_distances.data() + i * k;
    size_t filled = 0;
    for (int j = 0; j < table.k && filled < k; ++j) {
      const int neighbour = renumber[static_cast<size_t>(table.Row(old_row)[j])];
      if (neighbour < 0) break;  // a removed point: the rest of the row is not the k nearest
      row[filled] = neighbour;
      row_d2[filled] = table.RowDistances(old_row)[j];
      ++filled;
    }
    if (filled < k) {
      kept_index.Knn(kept_index.points()[i], out.k, &nn, &d2);
      std::copy(nn.begin(), nn.end(), row);
      std::copy(d2.begin(), d2.end(), row_d2);
    }
  }
  return out;
}

double MeanNearestDistance(const NeighborIndex& index, int samples) {
  const size_t n = index.size();
  const size_t stride = std::max<size_t>(1, n / static_cast<size_t>(std::max(1, samples)));
  std::vector<int> nn;
  std::vector<double> d2;
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < n; i += stride) {
    index.Knn(index.points()[i], 2, &nn, &d2);
    if (d2.size() < 2) continue;
    sum += std::sqrt(d2[1]);
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace graspfill::repair
