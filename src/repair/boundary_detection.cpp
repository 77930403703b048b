// SPDX-License-Identifier: BSD-3-Clause
#include "boundary_detection.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "geometry/plane_fit.hpp"

namespace graspfill::repair {

void BoundaryConfig::Validate() const {
  if (k < 3) {
    throw std::invalid_argument("BoundaryConfig: k must be >= 3, got " + std::to_string(k));
  }
  if (confirm_k != 0 && confirm_k <= k) {
    throw std::invalid_argument("BoundaryConfig: confirm_k must be 0 or > k, got " +
                                std::to_string(confirm_k));
  }
  if (!(angle_threshold_rad > 0.0 && angle_threshold_rad < 2.0 * M_PI)) {
    throw std::invalid_argument("BoundaryConfig: angle_threshold_rad must be in (0, 2*pi), got " +
                                std::to_string(angle_threshold_rad));
  }
}

namespace {

// Unit normal of the least-squares plane of `points[nn]`, or zero when they
// all coincide.
Eigen::Vector3f PlaneNormal(const PointList& points, const std::vector<int>& nn) {
  const auto neighbour = [&](size_t i) -> Eigen::Vector3d {
    return points[static_cast<size_t>(nn[i])].cast<double>();
  };
  const geometry::PlaneFit fit = geometry::FitPlane(nn.size(), neighbour, geometry::EigenSolve::kClosedForm);
  if (!(fit.eigenvalues.sum() > 0.0)) return Eigen::Vector3f::Zero();
  return fit.normal.cast<float>();
}

// A direction's "diamond angle" in [0, 4): monotone in its polar angle
// in [0, 2*pi) (0, 1, 2, 3 at 0, 90, 180, 270 degrees), one division
// instead of an atan2. (x, y) must not be (0, 0).
float DiamondAngle(float x, float y) {
  if (y >= 0.0f) return x >= 0.0f ? y / (x + y) : 1.0f - x / (y - x);
  return x < 0.0f ? 2.0f - y / (-x - y) : 3.0f + x / (x - y);
}

// One projected neighbour direction: its (u, v) coordinates and key.
struct Direction2 {
  float key;  // DiamondAngle(x, y)
  float x, y;
};

struct AngularGap {
  float angle_rad{0.0f};
  Eigen::Vector3f direction{Eigen::Vector3f::Zero()};
};

// The quick test before the sort: the directions' keys binned into 32
// sectors of [0, 4). DiamondAngle turns at most 2 rad per key unit (dθ/dk
// is 1 to 2 within a quadrant), so a gap of angle a between consecutive
// directions leaves an open key interval longer than a / 2 empty, which
// holds at least floor(a / 2 / w) - 1 whole sectors of width w.
constexpr int kSectors = 32;

// The threshold as a DiamondAngle key, and the run of empty sectors a gap
// wider than it leaves (computed once per call, not per point).
struct GapThreshold {
  float key{0.0f};
  int empty_run{0};
};

GapThreshold MakeGapThreshold(double angle_rad) {
  GapThreshold t;
  t.key = DiamondAngle(static_cast<float>(std::cos(angle_rad)), static_cast<float>(std::sin(angle_rad)));
  // The key back as an angle: keys below 1 are the first quadrant's,
  // tan(angle) = k / (1 - k); past pi/2 each quadrant adds pi/2.
  const float quadrants = std::floor(t.key);
  const float k = t.key - quadrants;
  const double angle = quadrants * M_PI_2 + std::atan2(k, 1.0f - k);
  t.empty_run = static_cast<int>(std::floor(angle / 2.0 / (4.0 / kSectors))) - 1;
  return t;
}

// False when no run of `run` empty sectors exists: then no gap is wider
// than the threshold and the point is interior (most are).
bool MayHaveGap(uint32_t occupied, int run) {
  if (run < 1) return true;
  uint32_t empty_run = ~occupied;
  for (int r = 1; r < run && empty_run != 0; ++r) {
    empty_run &= ~((occupied >> r) | (occupied << (kSectors - r)));
  }
  return empty_run != 0;
}

// The maximum-angle criterion at P: true when the directions from P to its
// neighbours `nn`, projected on the plane of `normal`, leave an angular gap
// wider than the threshold; then `gap` gets that widest gap [rad] and its unit
// bisector, in the plane. `dirs` is scratch space.
bool HasWideGap(const PointList& points, const std::vector<int>& nn, const Eigen::Vector3f& p,
                const Eigen::Vector3f& normal, const GapThreshold& threshold, std::vector<Direction2>* dirs,
                AngularGap* gap) {
  // Any orthonormal basis (u, v) of the tangent plane will do: the
  // criterion only looks at differences of angles.
  const Eigen::Vector3f u = normal.unitOrthogonal();
  const Eigen::Vector3f v = normal.cross(u);
  dirs->clear();
  uint32_t occupied = 0;  // bit s: some direction's key in sector s
  for (const int j : nn) {
    // P'Q' is the projection of PQ on the plane: its (u, v) coordinates.
    const Eigen::Vector3f d = points[static_cast<size_t>(j)] - p;
    const float x = d.dot(u);
    const float y = d.dot(v);
    // Skips P itself, its duplicates and neighbours straight along the
    // normal, whose direction in the plane is meaningless.
    if (x * x + y * y <= 1e-8f * d.squaredNorm()) continue;
    const float key = DiamondAngle(x, y);
    dirs->push_back({key, x, y});
    occupied |= 1u << std::min(static_cast<int>(key * (kSectors / 4.0f)), kSectors - 1);
  }
  if (dirs->empty()) return false;
  if (!MayHaveGap(occupied, threshold.empty_run)) return false;
  // Insertion sort: a few dozen directions, mostly short moves.
  for (size_t a = 1; a < dirs->size(); ++a) {
    const Direction2 dir = (*dirs)[a];
    size_t b = a;
    for (; b > 0 && (*dirs)[b - 1].key > dir.key; --b) (*dirs)[b] = (*dirs)[b - 1];
    (*dirs)[b] = dir;
  }
  // The gap between consecutive directions a, b (counterclockwise) is the
  // polar angle of (a.b, a x b): compare those by their diamond angles too,
  // the wrap-around pair (last, first) included. A single direction leaves
  // a full turn.
  const size_t n = dirs->size();
  size_t widest = n - 1;  // the gap from dirs[widest] to the next one
  float widest_key = 4.0f;
  if (n > 1) {
    widest_key = -1.0f;
    for (size_t a = 0; a < n; ++a) {
      const Direction2& d0 = (*dirs)[a];
      const Direction2& d1 = (*dirs)[(a + 1) % n];
      float cross = d0.x * d1.y - d0.y * d1.x;
      // Keys less than 1 apart are less than 2 rad apart, so the true
      // cross product is >= 0: a negative one is rounding between two
      // (nearly) coincident directions, which would read as a full turn.
      const float key_step = a + 1 < n ? d1.key - d0.key : d1.key + 4.0f - d0.key;
      if (key_step < 1.0f) cross = std::max(cross, 0.0f);
      const float key = DiamondAngle(d0.x * d1.x + d0.y * d1.y, cross);
      if (key > widest_key) {
        widest_key = key;
        widest = a;
      }
    }
  }
  if (widest_key <= threshold.key) return false;
  // Only now the true angles, for the few boundary points.
  const Direction2& d0 = (*dirs)[widest];
  const Direction2& d1 = (*dirs)[(widest + 1) % n];
  float angle = n > 1 ? std::atan2(d0.x * d1.y - d0.y * d1.x, d0.x * d1.x + d0.y * d1.y)
                      : static_cast<float>(2.0 * M_PI);
  if (angle <= 0.0f) angle += static_cast<float>(2.0 * M_PI);  // beyond pi
  const float mid = std::atan2(d0.y, d0.x) + 0.5f * angle;
  gap->angle_rad = angle;
  gap->direction = std::cos(mid) * u + std::sin(mid) * v;
  return true;
}

}  // namespace

std::vector<int> DetectBoundaryPoints(const NeighborIndex& index, const BoundaryConfig& config,
                                      std::vector<Eigen::Vector3f>* normals,
                                      std::vector<BoundaryPointInfo>* info, const KnnTable* table,
                                      const std::vector<int>* candidates) {
  config.Validate();
  const PointList& points = index.points();
  const size_t n = points.size();
  if (normals != nullptr) normals->assign(n, Eigen::Vector3f::Zero());
  if (info != nullptr) info->clear();

  const GapThreshold threshold = MakeGapThreshold(config.angle_threshold_rad);
  const size_t max_k = static_cast<size_t>(std::max(config.k, config.confirm_k)) + 1;
  // Buffers reused across points: no allocation in the loop once they have
  // grown to max_k.
  std::vector<int> nn;
  std::vector<double> d2;
  std::vector<Direction2> dirs;
  nn.reserve(max_k);
  d2.reserve(max_k);
  dirs.reserve(max_k);
  std::vector<int> boundary;

  const size_t first_k = static_cast<size_t>(config.k) + 1;
  if (table != nullptr && (table->size() != n || table->k < static_cast<int>(std::min(first_k, n)))) {
    throw std::invalid_argument("DetectBoundaryPoints: the kNN table does not match the index");
  }
  const size_t count = candidates != nullptr ? candidates->size() : n;
  // The candidates' first neighbours in one batch (same answers as a query
  // each, a few times faster).
  KnnTable candidate_table;
  if (candidates != nullptr) {
    for (int i : *candidates) {
      if (i < 0 || static_cast<size_t>(i) >= n)
        throw std::invalid_argument("DetectBoundaryPoints: candidate out of range");
    }
    if (table == nullptr) candidate_table = index.KnnOf(*candidates, config.k + 1);
  }
  // A boundary point, with its gap's direction and the spacing of the
  // neighbourhood it was judged on.
  const auto accept = [&](size_t i, const AngularGap& gap) {
    boundary.push_back(static_cast<int>(i));
    if (info != nullptr && nn.size() > 1) {
      // Density from the neighbourhood: its nn.size() - 1 neighbours fill
      // the covered part (2*pi - gap) of the disc out to the farthest one.
      const double covered = 1.0 - gap.angle_rad / (2.0 * M_PI);
      const double neighbours = static_cast<double>(nn.size() - 1);
      const double spacing = std::sqrt(d2.back() * M_PI * covered / neighbours);
      info->push_back({gap.direction, static_cast<float>(spacing)});
    } else if (info != nullptr) {
      info->push_back({gap.direction, 0.0f});
    }
  };
  std::vector<int> flagged;  // by the first look, for the wider one
  for (size_t c = 0; c < count; ++c) {
    const size_t i = candidates != nullptr ? static_cast<size_t>((*candidates)[c]) : c;
    const Eigen::Vector3f& p = points[i];
    if (table != nullptr || candidate_table.k > 0) {
      const KnnTable& t = table != nullptr ? *table : candidate_table;
      const size_t r = table != nullptr ? i : c;
      const size_t cols = std::min(first_k, static_cast<size_t>(t.k));
      nn.assign(t.Row(r), t.Row(r) + cols);
      d2.assign(t.RowDistances(r), t.RowDistances(r) + cols);
    } else {
      index.Knn(p, config.k + 1, &nn, &d2);
    }
    const Eigen::Vector3f normal = PlaneNormal(points, nn);
    if (normals != nullptr) (*normals)[i] = normal;
    AngularGap gap;
    if (normal.isZero() || !HasWideGap(points, nn, p, normal, threshold, &dirs, &gap)) {
      continue;
    }
    if (config.confirm_k > 0) {
      flagged.push_back(static_cast<int>(i));
    } else {
      accept(i, gap);
    }
  }
  if (flagged.empty()) return boundary;
  // The wider look, only for the few points the first one flagged (their
  // neighbours in one batch: the same as a query each, a few times
  // faster); its gap direction is the steadier one.
  const KnnTable wide = index.KnnOf(flagged, config.confirm_k + 1);
  for (size_t r = 0; r < flagged.size(); ++r) {
    const size_t i = static_cast<size_t>(flagged[r]);
    nn.assign(wide.Row(r), wide.Row(r) + wide.k);
    d2.assign(wide.RowDistances(r), wide.RowDistances(r) + wide.k);
    const Eigen::Vector3f wide_normal = PlaneNormal(points, nn);
    AngularGap gap;
    if (wide_normal.isZero() || !HasWideGap(points, nn, points[i], wide_normal, threshold, &dirs, &gap)) {
      continue;
    }
    accept(i, gap);
  }
  return boundary;
}

}  // namespace graspfill::repair
