// SPDX-License-Identifier: BSD-3-Clause
#include "neighbor_index.hpp"

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

// Smallest box edge the grid works with: relative to the box, so that any
// scale works, and never 0.
float MinExtent(const Eigen::AlignedBox3f& box) {
  return std::max(1e-6f * box.sizes().maxCoeff(), std::numeric_limits<float>::min());
}

}  // namespace

struct NeighborIndex::Impl {
  Eigen::Vector3f origin{0, 0, 0};
  float cell{1.0f};
  int n[3]{1, 1, 1};
  std::vector<int> cell_start;  // cells + 1 offsets into `order`/`sorted`
  std::vector<int> order;       // point indices, grouped by cell
  PointList sorted;             // the points in that order
  // The grid covers `box` (robust: the bulk of the points, see
  // RobustBox); the few points outside it ("far": stray points) are kept
  // in a list of their own and searched by brute force, so that two stray
  // points a kilometre away do not coarsen the grid into one cell.
  Eigen::AlignedBox3f box;
  std::vector<int> far;  // indices of the points outside `box`
  // Median distance to the 21st neighbour, measured when the grid is
  // built (0: not measured): AllKnn's block must reach past it.
  double typical_k_radius{0.0};

  // Grid over `box` with cubic cells of `cell` [m] (coarsened until the
  // grid has at most ~4 cells per point), points counting-sorted by cell.
  void Build(const PointList& points, double cell);

  bool Inside(const Eigen::Vector3f& p) const {
    return (p.array() >= box.min().array()).all() && (p.array() <= box.max().array()).all();
  }
  // Lower bound on the distance from q to any far point: its distance to
  // the outside of `box` (0 outside it; infinite when there are none).
  double FarBound(const Eigen::Vector3d& q) const {
    if (far.empty()) return std::numeric_limits<double>::infinity();
    double d = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      d = std::min({d, q[a] - static_cast<double>(box.min()[a]), static_cast<double>(box.max()[a]) - q[a]});
    }
    return std::max(d, 0.0);
  }
  void CollectFar(const PointList& points, const Eigen::Vector3d& q, std::vector<Candidate>* out) const {
    for (int i : far) out->emplace_back((points[static_cast<size_t>(i)].cast<double>() - q).squaredNorm(), i);
  }

  int CellOf(float x, int axis) const {
    // In double and clamped before the conversion: far or NaN coordinates
    // must not overflow int.
    const double i = std::floor((static_cast<double>(x) - origin[axis]) / cell);
    if (!(i >= 0.0)) return 0;
    return static_cast<int>(std::min(i, static_cast<double>(n[axis] - 1)));
  }
  int Flat(int x, int y, int z) const { return (z * n[1] + y) * n[0] + x; }

  // Adds the points of cell (x, y, z) to `out`.
  void Collect(int x, int y, int z, const Eigen::Vector3d& q, std::vector<Candidate>* out) const {
    const int c = Flat(x, y, z);
    for (int j = cell_start[c]; j < cell_start[c + 1]; ++j) {
      out->emplace_back((sorted[j].cast<double>() - q).squaredNorm(), order[j]);
    }
  }

  // Calls visit(c) for each cell c at Chebyshev distance exactly `r` from
  // `centre`, until one returns true (then true).
  template <typename Visit>
  bool VisitShell(const int centre[3], int r, const Visit& visit) const {
    const int z0 = std::max(0, centre[2] - r), z1 = std::min(n[2] - 1, centre[2] + r);
    const int y0 = std::max(0, centre[1] - r), y1 = std::min(n[1] - 1, centre[1] + r);
    const int x0 = std::max(0, centre[0] - r), x1 = std::min(n[0] - 1, centre[0] + r);
    for (int z = z0; z <= z1; ++z) {
      for (int y = y0; y <= y1; ++y) {
        if (std::abs(z - centre[2]) == r || std::abs(y - centre[1]) == r) {
          for (int x = x0; x <= x1; ++x) {
            if (visit(Flat(x, y, z))) return true;
          }
        } else {  // inside the shell's slab only its two x faces are new
          if (centre[0] - r >= 0 && visit(Flat(centre[0] - r, y, z))) return true;
          if (centre[0] + r < n[0] && visit(Flat(centre[0] + r, y, z))) return true;
        }
      }
    }
    return false;
  }

  // Adds the points of the cells at Chebyshev distance exactly `r`.
  void CollectShell(const int centre[3], int r, const Eigen::Vector3d& q, std::vector<Candidate>* out) const {
    VisitShell(centre, r, [&](int c) {
      for (int j = cell_start[c]; j < cell_start[c + 1]; ++j) {
        out->emplace_back((sorted[j].cast<double>() - q).squaredNorm(), order[j]);
      }
      return false;
    });
  }

  // The widest shell that can hold a cell.
  int MaxShell() const { return std::max({n[0], n[1], n[2]}); }

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

NeighborIndex::NeighborIndex(const PointList& points) : points_(points), impl_(std::make_unique<Impl>()) {
  if (points.empty()) throw std::invalid_argument("NeighborIndex: empty cloud");
  // First about one cell per point over the bounding box; then cells of
  // ~1.25x the typical distance to the 20th neighbour (the median of 64
  // points'; the cells change the speed only, never an answer): the 27
  // cells around a point then hold its 20 nearest with few others (on a
  // rotated surface sample the first grid has cells ~2x larger and ~2x the
  // candidates).
  constexpr size_t kBoxSamples = 4096;
  impl_->box = RobustBox(points, kBoxSamples);
  const Eigen::Vector3f extent = impl_->box.sizes().cwiseMax(MinExtent(impl_->box));
  const double count = static_cast<double>(points.size());
  impl_->Build(points, std::cbrt(static_cast<double>(extent.x()) * extent.y() * extent.z() / count));
  constexpr int kTypicalK = 21;
  if (points.size() > 4 * kTypicalK) {
    std::vector<int> nn;
    std::vector<double> d2;
    std::vector<double> radius;
    const size_t stride = std::max<size_t>(1, points.size() / 64);
    for (size_t i = 0; i < points.size(); i += stride) {
      Knn(points[i], kTypicalK, &nn, &d2);
      radius.push_back(std::sqrt(d2.back()));
    }
    std::nth_element(radius.begin(), radius.begin() + static_cast<long>(radius.size() / 2), radius.end());
    const double cell = 1.25 * radius[radius.size() / 2];
    impl_->typical_k_radius = radius[radius.size() / 2];
    if (cell > 0.0 && cell < impl_->cell) impl_->Build(points, cell);
  }
}

void NeighborIndex::Impl::Build(const PointList& points, double cell) {
  Impl& g = *this;
  const Eigen::Vector3f extent = box.sizes().cwiseMax(MinExtent(box));
  far.clear();
  for (size_t i = 0; i < points.size(); ++i) {
    if (!Inside(points[i])) far.push_back(static_cast<int>(i));
  }
  const double count = static_cast<double>(points.size() - far.size());
  // Relative to the extent, not a fixed length: a cloud scaled by 1e-38 is
  // as cheap as any other (its cells would otherwise all be one).
  cell = std::max({cell, 1e-6 * static_cast<double>(extent.maxCoeff()), 1e-300});
  if (!std::isfinite(cell)) cell = std::max(1.0, static_cast<double>(extent.maxCoeff()));
  auto cells = [&](double c) {
    double total = 1.0;
    for (int a = 0; a < 3; ++a) total *= std::floor(extent[a] / c) + 1.0;
    return total;
  };
  while (cells(cell) > 4.0 * count + 64.0) cell *= 1.25;
  g.cell = static_cast<float>(cell);
  g.origin = box.min();
  // cells() <= 4 count + 64 above: each axis is small enough for int.
  for (int a = 0; a < 3; ++a) g.n[a] = static_cast<int>(std::min(std::floor(extent[a] / cell), 1e7)) + 1;

  // Counting sort of the points inside the box by cell.
  const size_t num_cells = static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2];
  std::vector<int> cell_of(points.size(), -1);
  g.cell_start.assign(num_cells + 1, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!Inside(p)) continue;
    cell_of[i] = g.Flat(g.CellOf(p.x(), 0), g.CellOf(p.y(), 1), g.CellOf(p.z(), 2));
    ++g.cell_start[static_cast<size_t>(cell_of[i]) + 1];
  }
  for (size_t c = 0; c < num_cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  std::vector<int> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  const size_t inside = points.size() - far.size();
  g.order.resize(inside);
  g.sorted.resize(inside);
  for (size_t i = 0; i < points.size(); ++i) {
    if (cell_of[i] < 0) continue;
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
  const double far_bound = g.FarBound(q);
  for (int r = 1;; ++r) {
    g.CollectShell(centre, r, q, &found);
    const double bound = g.Unsearched(centre, r, q);
    const bool enough = found.size() >= want;
    if (enough) {
      std::nth_element(found.begin(), found.begin() + static_cast<long>(want - 1), found.end());
      const double kth = found[want - 1].first;
      if (kth <= std::min(bound, far_bound) * std::min(bound, far_bound)) break;  // no far point needed
    }
    if (std::isinf(bound) || (enough && found[want - 1].first <= bound * bound)) {
      // The grid is done; the far points may still be nearer.
      g.CollectFar(points_, q, &found);
      break;
    }
  }
  want = std::min(want, found.size());
  std::partial_sort(found.begin(), found.begin() + static_cast<long>(want), found.end());
  for (size_t j = 0; j < want; ++j) {
    indices->push_back(found[j].second);
    if (squared_distances) squared_distances->push_back(found[j].first);
  }
}

KnnTable NeighborIndex::AllKnn(int k) const { return Table(k, nullptr); }

KnnTable NeighborIndex::KnnOf(const std::vector<int>& queries, int k) const {
  std::vector<int> row_of(points_.size(), -1);
  for (size_t r = 0; r < queries.size(); ++r) {
    const int i = queries[r];
    if (i < 0 || static_cast<size_t>(i) >= points_.size() || row_of[static_cast<size_t>(i)] >= 0) {
      throw std::invalid_argument("NeighborIndex::KnnOf: a query is out of range or repeated");
    }
    row_of[static_cast<size_t>(i)] = static_cast<int>(r);
  }
  return Table(k, &row_of);
}

KnnTable NeighborIndex::Table(int k, const std::vector<int>* row_of) const {
  const Impl& g = *impl_;
  KnnTable table;
  table.k = std::max(0, std::min(k, static_cast<int>(points_.size())));
  if (table.k == 0) return table;
  const size_t want = static_cast<size_t>(table.k);
  // Point -> its row (-1: not asked); every point, in order, without `row_of`.
  const auto row_at = [&](int point) { return row_of ? (*row_of)[static_cast<size_t>(point)] : point; };
  size_t rows = points_.size();
  if (row_of)
    rows = static_cast<size_t>(std::count_if(row_of->begin(), row_of->end(), [](int r) { return r >= 0; }));
  table.indices.resize(rows * want);
  table.squared_distances.resize(rows * want);
  // The candidates of one cell (its 3 x 3 x 3 block) as float columns, so
  // that the distances of a query to all of them vectorize; the few that
  // can be among the k nearest are then ranked exactly, in double.
  std::vector<float> cx, cy, cz, dist, scratch;
  std::vector<int> cid;
  std::vector<Candidate> exact;
  std::vector<int> fallback_nn;
  std::vector<double> fallback_d2;
  float guess = 0.0f;  // squared; 0: none yet
  // The block around a cell: one cell each way, two where a typical k-th
  // distance (scaled from the 21st's as on a surface) exceeds a cell, as
  // on a sparse copy, which keeps the finer first grid: one cell each way
  // sent up to 90% of its queries to Knn.
  const double k_radius = g.typical_k_radius * std::sqrt(static_cast<double>(table.k) / 21.0);
  const int reach = k_radius > g.cell ? 2 : 1;
  for (int z = 0; z < g.n[2]; ++z) {
    for (int y = 0; y < g.n[1]; ++y) {
      for (int x = 0; x < g.n[0]; ++x) {
        const int c = g.Flat(x, y, z);
        if (g.cell_start[c] == g.cell_start[c + 1]) continue;
        if (row_of && std::none_of(g.order.begin() + g.cell_start[c], g.order.begin() + g.cell_start[c + 1],
                                   [&](int point) { return row_at(point) >= 0; })) {
          continue;
        }
        cx.clear(), cy.clear(), cz.clear(), cid.clear();
        const int x0 = std::max(0, x - reach), x1 = std::min(g.n[0] - 1, x + reach);
        for (int bz = std::max(0, z - reach); bz <= std::min(g.n[2] - 1, z + reach); ++bz) {
          for (int by = std::max(0, y - reach); by <= std::min(g.n[1] - 1, y + reach); ++by) {
            // A row of cells along x is contiguous in `sorted`.
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
          const int r = row_at(point);
          if (r < 0) continue;
          int* row = table.indices.data() + static_cast<size_t>(r) * want;
          double* row_d2 = table.squared_distances.data() + static_cast<size_t>(r) * want;
          for (size_t m = 0; m < num; ++m) {
            const float dx = cx[m] - qf.x(), dy = cy[m] - qf.y(), dz = cz[m] - qf.z();
            dist[m] = dx * dx + dy * dy + dz * dz;
          }
          // The k nearest, ranked exactly. First among the candidates
          // within a guess (the last query's k-th distance x 1.1:
          // neighbouring points have similar ones), ~k of the ~100-200:
          // they hold the k nearest when the k-th of them lies clearly
          // inside the guess (float rounding is ~1e-6 relative). Else among
          // those within the k-th smallest float distance of all of them.
          const Eigen::Vector3d q = qf.cast<double>();
          const auto rank_within = [&](float limit_d2) {
            exact.clear();
            for (size_t m = 0; m < num; ++m) {
              if (dist[m] <= limit_d2) {
                const int slot = cid[m];
                exact.emplace_back((g.sorted[slot].cast<double>() - q).squaredNorm(), g.order[slot]);
              }
            }
            // Only the k nearest need an order (a few dozen of up to ~100).
            if (exact.size() > want) {
              std::nth_element(exact.begin(), exact.begin() + static_cast<long>(want - 1), exact.end());
              std::sort(exact.begin(), exact.begin() + static_cast<long>(want));
            } else {
              std::sort(exact.begin(), exact.end());
            }
          };
          double kth = std::numeric_limits<double>::infinity();
          if (num >= want) {
            if (guess > 0.0f) rank_within(guess);
            if (guess <= 0.0f || exact.size() < want ||
                !(exact[want - 1].first * (1.0 + 1e-5) < static_cast<double>(guess))) {
              scratch.assign(dist.begin(), dist.end());
              std::nth_element(scratch.begin(), scratch.begin() + static_cast<long>(want - 1), scratch.end());
              rank_within(scratch[want - 1] * (1.0f + 1e-5f) + 1e-30f);
            }
            kth = exact[want - 1].first;
            guess = static_cast<float>(1.21 * kth);
          }
          // Exact only if nothing outside the block can be nearer.
          const double bound = std::min(g.Unsearched(centre, reach, q), g.FarBound(q));
          if (!(std::isinf(bound) ? num >= want : kth < 0.999 * bound * bound)) {
            Knn(points_[static_cast<size_t>(point)], table.k, &fallback_nn, &fallback_d2);
            std::copy(fallback_nn.begin(), fallback_nn.end(), row);
            std::copy(fallback_d2.begin(), fallback_d2.end(), row_d2);
            continue;
          }
          for (size_t m = 0; m < want; ++m) {
            row[m] = exact[m].second;
            row_d2[m] = exact[m].first;
          }
        }
      }
    }
  }
  for (int point : g.far) {
    const int r = row_at(point);
    if (r < 0) continue;
    Knn(points_[static_cast<size_t>(point)], table.k, &fallback_nn, &fallback_d2);
    std::copy(fallback_nn.begin(), fallback_nn.end(), table.indices.data() + static_cast<size_t>(r) * want);
    std::copy(fallback_d2.begin(), fallback_d2.end(),
              table.squared_distances.data() + static_cast<size_t>(r) * want);
  }
  return table;
}

void NeighborIndex::Radius(const Eigen::Vector3f& query, double radius_m, std::vector<int>* indices,
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
  // (Past the largest grid dimension every cell has been searched: an
  // infinite radius ends there.)
  for (int r = 1; r <= g.MaxShell() && g.Unsearched(centre, r - 1, q) <= radius_m; ++r) {
    g.CollectShell(centre, r, q, &found);
  }
  if (g.FarBound(q) <= radius_m) g.CollectFar(points_, q, &found);
  const double r2 = radius_m * radius_m;
  found.erase(std::remove_if(found.begin(), found.end(), [r2](const Candidate& c) { return c.first > r2; }),
              found.end());
  std::sort(found.begin(), found.end());
  for (const Candidate& c : found) {
    indices->push_back(c.second);
    if (squared_distances) squared_distances->push_back(c.first);
  }
}

bool NeighborIndex::AnyWithin(const Eigen::Vector3f& query, double radius_m) const {
  return AnyWithinIf(query, radius_m, [](const Eigen::Vector3f&) { return true; });
}

bool NeighborIndex::AnyWithin(const Eigen::Vector3f& query, double radius_m,
                              const std::function<bool(const Eigen::Vector3f&)>& accept) const {
  return AnyWithinIf(query, radius_m, accept);
}

template <typename Accept>
bool NeighborIndex::AnyWithinIf(const Eigen::Vector3f& query, double radius_m, const Accept& accept) const {
  const Impl& g = *impl_;
  if (!(radius_m >= 0.0)) return false;
  const Eigen::Vector3d q = query.cast<double>();
  const double r2 = radius_m * radius_m;
  const auto near = [&](const Eigen::Vector3f& p) {
    return (p.cast<double>() - q).squaredNorm() <= r2 && accept(p);
  };
  const int centre[3] = {g.CellOf(query.x(), 0), g.CellOf(query.y(), 1), g.CellOf(query.z(), 2)};
  const auto cell_has = [&](int c) {
    for (int j = g.cell_start[c]; j < g.cell_start[c + 1]; ++j) {
      if (near(g.sorted[j])) return true;
    }
    return false;
  };
  // The cells Radius searches, shell by shell, until a hit.
  if (cell_has(g.Flat(centre[0], centre[1], centre[2]))) return true;
  for (int r = 1; r <= g.MaxShell() && g.Unsearched(centre, r - 1, q) <= radius_m; ++r) {
    if (g.VisitShell(centre, r, cell_has)) return true;
  }
  if (g.FarBound(q) <= radius_m) {
    for (int i : g.far) {
      if (near(points_[static_cast<size_t>(i)])) return true;
    }
  }
  return false;
}

// The box the grid covers: the points' bounding box, cut down around the
// bulk when a few points lie far from it. Per axis, the 0.1% and 99.9%
// quantiles widened by half their distance on each side: a clean cloud's
// extremes lie inside that, so its box (and every result) is the bounding
// box as before; stray points beyond it are searched apart (Impl::far).
Eigen::AlignedBox3f RobustBox(const PointList& points, size_t max_samples) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) box.extend(p);
  }
  const size_t stride = max_samples > 0 ? std::max<size_t>(1, points.size() / max_samples) : 1;
  size_t finite = 0;  // of the points the quantiles read
  for (size_t i = 0; i < points.size(); i += stride) finite += points[i].allFinite();
  if (finite < 64) return box;
  std::vector<float> values;
  values.reserve(finite);
  const size_t lo_rank = finite / 1000;
  const size_t hi_rank = finite - 1 - lo_rank;
  for (int a = 0; a < 3; ++a) {
    values.clear();
    for (size_t i = 0; i < points.size(); i += stride) {
      if (points[i].allFinite()) values.push_back(points[i][a]);
    }
    std::nth_element(values.begin(), values.begin() + static_cast<long>(lo_rank), values.end());
    const float lo = values[lo_rank];
    // The high rank lies among those after the low one (partitioned above).
    std::nth_element(values.begin() + static_cast<long>(lo_rank) + 1,
                     values.begin() + static_cast<long>(hi_rank), values.end());
    const float hi = values[hi_rank];
    const double margin = 0.5 * (static_cast<double>(hi) - lo);
    box.min()[a] = std::max(box.min()[a], static_cast<float>(lo - margin));
    box.max()[a] = std::min(box.max()[a], static_cast<float>(hi + margin));
  }
  return box;
}

KnnTable RestrictTable(const KnnTable& table, const std::vector<int>& kept, const NeighborIndex& kept_index) {
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
