// SPDX-License-Identifier: BSD-3-Clause
#include "ransac_planes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "plane_fit.hpp"

namespace graspfill::repair::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

// Hypotheses are scored on this many evenly strided points (the winner is
// then refitted on all of them): scoring every point of a 2-3k boundary
// for every hypothesis would cost ~1 ms per plane...
constexpr size_t kScoringPoints = 384;
// ... and first on this many, to drop hopeless hypotheses cheaply.
constexpr size_t kPreemptivePoints = 64;
// Cloud points against which a hypothesis is checked for being a cut.
constexpr size_t kSideSamplePoints = 2048;
// Cut-mode seeds: directions, and the share of the points (at least
// kSeedMinPoints) farthest along each that a seed plane is fitted to.
constexpr int kSeedDirections = 64;
constexpr size_t kSeedFraction = 12;
constexpr size_t kSeedMinPoints = 24;
// A hypothesis with more than this fraction of its inliers on one plane
// already found is that plane again (a shifted or tilted copy through the
// same band). Two genuine planes share only their intersection line: a
// cuboid's top shares a quarter of its rim with each face.
constexpr double kMaxSharedFraction = 0.5;

std::vector<int> Strided(const std::vector<int>& indices, size_t at_most) {
  const size_t stride = std::max<size_t>(1, (indices.size() + at_most - 1) / at_most);
  std::vector<int> out;
  for (size_t k = 0; k < indices.size(); k += stride) out.push_back(indices[k]);
  return out;
}

}  // namespace

bool FitPlaneOf(const std::vector<Vec3>& points, const std::vector<int>& indices, Vec3* normal,
                double* offset) {
  if (indices.size() < 3) return false;
  const PlaneFit fit = FitPlane(
      indices.size(), [&](size_t k) -> const Vec3& { return points[static_cast<size_t>(indices[k])]; },
      EigenSolve::kIterative);
  *normal = fit.normal;
  *offset = fit.offset();
  return true;
}

std::vector<int> PlaneInliers(const std::vector<Vec3>& points, const std::vector<int>& candidates,
                              const Vec3& normal, double offset, double distance) {
  std::vector<int> out;
  for (int i : candidates) {
    if (std::abs(normal.dot(points[static_cast<size_t>(i)]) - offset) <= distance) out.push_back(i);
  }
  return out;
}

RansacPlanes::RansacPlanes(const std::vector<Vec3>& points, const std::vector<Vec3>& cloud,
                           const RansacPlanesConfig& config, int min_inliers, std::optional<Vec3> hint)
    : points_(points),
      config_(config),
      min_inliers_(min_inliers),
      hint_(hint),
      rng_(config.seed),
      explained_(points.size(), 0) {
  for (size_t i = 0; i < points.size(); ++i) all_.push_back(static_cast<int>(i));
  all_scoring_ = Pack(Strided(all_, kScoringPoints));
  std::vector<Vec3> side;
  const size_t stride = std::max<size_t>(1, (cloud.size() + kSideSamplePoints - 1) / kSideSamplePoints);
  for (size_t i = 0; i < cloud.size(); i += stride) side.push_back(cloud[i]);
  // Shuffled, so that a plane through the cloud meets points on both of
  // its sides within the first few and is dropped early.
  for (size_t i = side.size(); i > 1; --i) std::swap(side[i - 1], side[rng_() % i]);
  side_sample_ = Pack(side);
  side_limit_ = static_cast<int>(config_.stray_fraction * static_cast<double>(side.size()));
}

// Seeds for the cut mode: for directions spread over the sphere
// (Fibonacci lattice), the least-squares plane of the boundary points
// farthest along it. Within the top's cone of directions these are arcs
// of the rim, and the local optimisation grows them to the whole rim: a
// small rim among many boundary points (an ellipsoid's, or a prism's
// among flagged edges) is found at once instead of after thousands of
// random triples.
// With an up hint, the hint and a ring of directions around it come
// first.
void RansacPlanes::MakeSeeds(const std::optional<Vec3>& hint) {
  const size_t n = points_.size();
  const size_t k = std::min(n, std::max<size_t>(kSeedMinPoints, n / kSeedFraction));
  std::vector<std::pair<double, int>> heights(n);
  std::vector<Vec3> dirs;
  if (hint) {
    dirs.push_back(*hint);
    const Vec3 u = hint->unitOrthogonal(), v = hint->cross(u);
    for (int i = 0; i < 6; ++i) {
      const double a = M_PI / 3 * i;
      dirs.push_back(
          (*hint + std::tan(config_.hint_ring_rad) * (std::cos(a) * u + std::sin(a) * v)).normalized());
    }
  }
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int s = 0; s < kSeedDirections; ++s) {
    const double z = 1.0 - 2.0 * (s + 0.5) / kSeedDirections;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs.emplace_back(r * std::cos(golden * s), r * std::sin(golden * s), z);
  }
  for (const Vec3& dir : dirs) {
    for (size_t i = 0; i < n; ++i) heights[i] = {-dir.dot(points_[i]), static_cast<int>(i)};
    std::nth_element(heights.begin(), heights.begin() + static_cast<long>(k) - 1, heights.end());
    std::vector<int> top(k);
    for (size_t i = 0; i < k; ++i) top[i] = heights[i].second;
    Vec3 normal;
    double offset;
    if (FitPlaneOf(points_, top, &normal, &offset)) seeds_.push_back({normal, offset});
  }
}

/// Adds the next plane; false when there is none with enough inliers.
bool RansacPlanes::FindNext(Mode mode) {
  const bool cut = mode == Mode::kCut;
  std::vector<int> pool;
  if (cut) {
    pool = all_;
  } else {
    for (int i : all_) {
      if (!explained_[static_cast<size_t>(i)]) pool.push_back(i);
    }
  }
  if (static_cast<int>(pool.size()) < min_inliers_) return false;
  const Packed scoring = cut ? all_scoring_ : Pack(Strided(pool, kScoringPoints));
  const Packed preemptive = Pack(Strided(scoring.index, kPreemptivePoints));
  const double threshold = config_.distance_m;
  const double log_miss = std::log(1.0 - config_.confidence);
  const double pre_scale = static_cast<double>(preemptive.size()) / static_cast<double>(scoring.size());
  const double min_score =
      min_inliers_ * static_cast<double>(scoring.size()) / static_cast<double>(pool.size());

  int best_score = static_cast<int>(std::ceil(min_score)) - 1;
  bool found = false;
  Vec3 best_normal = Vec3::UnitZ();
  double best_offset = 0.0;
  int needed = config_.max_iterations;
  std::vector<int> support;
  if (cut && seeds_.empty()) MakeSeeds(hint_);
  const int n_seeds = cut ? static_cast<int>(seeds_.size()) : 0;
  for (int it = 0; it < n_seeds + needed; ++it) {
    Vec3 n;
    double d;
    if (it < n_seeds) {
      n = seeds_[static_cast<size_t>(it)].first;
      d = seeds_[static_cast<size_t>(it)].second;
    } else {
      // Portable draws: mt19937_64's output is fixed by the standard, the
      // distributions are not; the modulo bias is negligible here.
      const Vec3& a = points_[static_cast<size_t>(pool[rng_() % pool.size()])];
      const Vec3& b = points_[static_cast<size_t>(pool[rng_() % pool.size()])];
      const Vec3& c = points_[static_cast<size_t>(pool[rng_() % pool.size()])];
      const Vec3 ab = b - a, ac = c - a;
      n = ab.cross(ac);
      const double norm = n.norm();
      // Repeated or collinear triples (a straight rim edge) fix no plane.
      if (norm == 0.0 || norm <= 1e-6 * ab.norm() * ac.norm()) continue;
      n /= norm;
      d = n.dot(a);
    }
    // Tilted rim triples keep about half their inliers (see above).
    const double floor = 0.4 * std::max<double>(best_score, min_score);
    if (preemptive.Count(n, d, threshold) < floor * pre_scale) continue;
    // Most planes through boundary points cut through the cloud: drop
    // them early (with a looser band, as the triple may still lean).
    if (cut && !OneSided(n, d, 2.0 * config_.side_band_m)) continue;
    int score = scoring.Count(n, d, threshold);
    // (No duplicate test yet: a seed or triple leaning over a face's top
    // edge shares most points with that face until its refit levels it.)
    if (score < floor) continue;
    for (int round = 0; round < 2; ++round) {
      scoring.Within(n, d, threshold, &support);
      for (int& k : support) k = scoring.index[static_cast<size_t>(k)];
      Vec3 n_ls;
      double d_ls;
      if (!FitPlaneOf(points_, support, &n_ls, &d_ls)) break;
      const int score_ls = scoring.Count(n_ls, d_ls, threshold);
      if (score_ls <= score) break;
      n = n_ls, d = d_ls, score = score_ls;
    }
    if (score <= best_score) continue;
    if (cut && (!OneSided(n, d, config_.side_band_m) || Duplicate(n, d))) continue;
    best_score = score;
    best_normal = n;
    best_offset = d;
    found = true;
    // Stop once a triple of this plane's points would have been drawn
    // with the configured confidence.
    const double w = static_cast<double>(score) / static_cast<double>(scoring.size());
    const double p_all = w * w * w;
    needed = p_all >= 1.0 ? std::max(0, it + 1 - n_seeds)
                          : static_cast<int>(std::min<double>(config_.max_iterations,
                                                              std::ceil(log_miss / std::log(1.0 - p_all))));
  }
  if (!found) return false;

  std::vector<int> inliers = PlaneInliers(points_, pool, best_normal, best_offset, threshold);
  Vec3 n;
  double d;
  if (FitPlaneOf(points_, inliers, &n, &d) &&
      !(cut && (!OneSided(n, d, config_.side_band_m) || Duplicate(n, d)))) {
    std::vector<int> refit = PlaneInliers(points_, pool, n, d, threshold);
    if (refit.size() >= inliers.size()) {
      best_normal = n, best_offset = d, inliers = std::move(refit);
    }
  }
  if (static_cast<int>(inliers.size()) < min_inliers_) return false;
  planes_.push_back({best_normal, best_offset, static_cast<int>(inliers.size())});
  // Only fresh-mode planes explain points (cut mode shares them).
  if (!cut) {
    for (int i : inliers) explained_[static_cast<size_t>(i)] = 1;
  }
  std::vector<int> on_plane;
  all_scoring_.Within(best_normal, best_offset, threshold, &on_plane);
  std::vector<uint8_t> mask(all_scoring_.size(), 0);
  for (int k : on_plane) mask[static_cast<size_t>(k)] = 1;
  masks_.push_back(std::move(mask));
  return true;
}
RansacPlanes::Packed RansacPlanes::Pack(const std::vector<int>& indices) const {
  Packed p;
  for (int i : indices) {
    const Vec3& q = points_[static_cast<size_t>(i)];
    p.x.push_back(static_cast<float>(q.x()));
    p.y.push_back(static_cast<float>(q.y()));
    p.z.push_back(static_cast<float>(q.z()));
    p.index.push_back(i);
  }
  return p;
}
RansacPlanes::Packed RansacPlanes::Pack(const std::vector<Vec3>& points) {
  Packed p;
  for (const Vec3& q : points) {
    p.x.push_back(static_cast<float>(q.x()));
    p.y.push_back(static_cast<float>(q.y()));
    p.z.push_back(static_cast<float>(q.z()));
  }
  return p;
}

// True if at most the strays of the cloud sample lie beyond the plane on
// one of its sides.
bool RansacPlanes::OneSided(const Vec3& n, double d, double band) const {
  const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()), nz = static_cast<float>(n.z()),
              df = static_cast<float>(d), bf = static_cast<float>(band);
  int above = 0, below = 0;
  // Blocks of 16 between the early-exit checks, so the loop vectorises.
  constexpr size_t kBlock = 16;
  const size_t n_points = side_sample_.size();
  for (size_t start = 0; start < n_points; start += kBlock) {
    const size_t end = std::min(n_points, start + kBlock);
    for (size_t k = start; k < end; ++k) {
      const float h = nx * side_sample_.x[k] + ny * side_sample_.y[k] + nz * side_sample_.z[k] - df;
      above += h > bf;
      below += h < -bf;
    }
    if (above > side_limit_ && below > side_limit_) return false;
  }
  return true;
}

// True if more than kMaxSharedFraction of the plane's inliers (in the
// scoring sample) are inliers of one plane already found.
bool RansacPlanes::Duplicate(const Vec3& n, double d) const {
  if (planes_.empty()) return false;
  all_scoring_.Within(n, d, config_.distance_m, &scratch_);
  for (const std::vector<uint8_t>& mask : masks_) {
    int shared = 0;
    for (int k : scratch_) shared += mask[static_cast<size_t>(k)];
    if (shared > kMaxSharedFraction * static_cast<double>(scratch_.size())) return true;
  }
  return false;
}

}  // namespace graspfill::repair::geometry
