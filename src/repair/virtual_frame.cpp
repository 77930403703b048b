#include "graspfill/repair/virtual_frame.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>

#include "convex_hull.hpp"

namespace graspfill::repair {
namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

// RANSAC hypotheses are scored on this many evenly strided boundary points
// (the winner is then refitted on all of them): scoring every point of a
// 2-3k boundary for every hypothesis would cost ~1 ms per plane...
constexpr size_t kScoringPoints = 384;
// ... and first on this many, to drop hopeless hypotheses cheaply.
constexpr size_t kPreemptivePoints = 64;
// Cloud points against which a hypothesis is checked for being a cut.
constexpr size_t kSideSamplePoints = 2048;
// Cut-mode seeds: directions, and the share of the boundary points (at
// least kSeedMinPoints) farthest along each that a seed plane is fitted to.
constexpr int kSeedDirections = 64;
constexpr size_t kSeedFraction = 12;
constexpr size_t kSeedMinPoints = 24;
// A plane with at most this fraction of the cloud beyond it (strays) has
// the cloud on one side.
constexpr double kStrayFraction = 0.002;
// A hypothesis with more than this fraction of its inliers on one plane
// already found is that plane again (a shifted or tilted copy through the
// same band). Two genuine planes share only their intersection line: a
// cuboid's top shares a quarter of its rim with each face.
constexpr double kMaxSharedFraction = 0.5;
// The most a cut's refit may turn it (see RefineCut).
constexpr double kMaxRefineAngleRad = 10.0 * M_PI / 180.0;
// Cuts less open than this are not refitted (they are no top).
constexpr double kMinRefineOpenFraction = 0.5;
// Cloud support points tested per plane for the open fraction.
constexpr int kOpenSamples = 512;
// Fewer cloud points on a plane than this: nothing contradicts "open".
constexpr int kMinOpenSupport = 10;

std::vector<Vec3> FinitePoints(const PointList& points) {
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) out.push_back(p.cast<double>());
  }
  return out;
}

// "Is any of the points within r of q": a dense grid of cell size >= r over
// the points' bounding box, so a query looks at the 27 cells around q.
class NearGrid {
 public:
  NearGrid(const std::vector<Vec3>& points, double r) : points_(points), r2_(r * r) {
    Eigen::AlignedBox3d box;
    for (const Vec3& p : points) box.extend(p);
    if (points.empty()) box.extend(Vec3::Zero());
    origin_ = box.min();
    const Vec3 extent = box.sizes();
    // A radius that is not a positive length finds nothing (r2_ is NaN or
    // 0); the grid still needs a usable cell.
    cell_ = r > 0.0 && std::isfinite(r) ? r : 1.0;
    // Stray points could make the box huge; coarser cells keep the grid
    // small and the 27-cell query still covers the radius. Doubled until
    // the grid fits (a cube-root rescale undershoots a long thin box: one
    // axis of 1e10 cells overflowed int and asked for 7 GB).
    constexpr double kMaxCells = 1 << 21;
    auto volume_cells = [&] {
      double v = 1.0;
      for (int a = 0; a < 3; ++a) v *= std::floor(extent[a] / cell_) + 1.0;
      return v;
    };
    while (!(volume_cells() <= kMaxCells)) cell_ *= 2.0;
    for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor(extent[a] / cell_)) + 1;
    const size_t cells = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
    start_.assign(cells + 1, 0);
    std::vector<size_t> cell_of(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      cell_of[i] = Flat(Cell(points[i]));
      ++start_[cell_of[i] + 1];
    }
    for (size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    order_.resize(points.size());
    std::vector<size_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<int>(i);
  }

  bool AnyWithin(const Vec3& q) const {
    const Eigen::Vector3i c = Cell(q);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const Eigen::Vector3i n = c + Eigen::Vector3i(dx, dy, dz);
          if ((n.array() < 0).any() || n.x() >= dims_[0] || n.y() >= dims_[1] ||
              n.z() >= dims_[2]) {
            continue;
          }
          const size_t f = Flat(n);
          for (size_t k = start_[f]; k < start_[f + 1]; ++k) {
            if ((points_[static_cast<size_t>(order_[k])] - q).squaredNorm() <= r2_) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  Eigen::Vector3i Cell(const Vec3& p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) {
      // Points outside the box map to out-of-range cells, which are skipped.
      const double v = std::floor((p[a] - origin_[a]) / cell_);
      c[a] = v == v ? static_cast<int>(std::clamp(v, -2.0, static_cast<double>(dims_[a]) + 1.0)) : -2;
    }
    return c;
  }
  size_t Flat(const Eigen::Vector3i& c) const {
    return (static_cast<size_t>(c.z()) * dims_[1] + c.y()) * dims_[0] + c.x();
  }

  const std::vector<Vec3>& points_;
  double r2_;
  double cell_;
  Vec3 origin_;
  int dims_[3]{1, 1, 1};
  std::vector<size_t> start_;
  std::vector<int> order_;
};

// Least-squares plane through points[idx]: the eigenvector of the smallest
// eigenvalue of their covariance. False when fewer than 3 points.
bool FitPlane(const std::vector<Vec3>& points, const std::vector<int>& idx, Vec3* normal,
              double* offset) {
  if (idx.size() < 3) return false;
  Vec3 mean = Vec3::Zero();
  for (int i : idx) mean += points[static_cast<size_t>(i)];
  mean /= static_cast<double>(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : idx) {
    const Vec3 d = points[static_cast<size_t>(i)] - mean;
    cov += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  *normal = eig.eigenvectors().col(0).normalized();
  *offset = normal->dot(mean);
  return true;
}

std::vector<int> Inliers(const std::vector<Vec3>& points, const std::vector<int>& candidates,
                         const Vec3& normal, double offset, double threshold) {
  std::vector<int> out;
  for (int i : candidates) {
    if (std::abs(normal.dot(points[static_cast<size_t>(i)]) - offset) <= threshold)
      out.push_back(i);
  }
  return out;
}

std::vector<int> Strided(const std::vector<int>& indices, size_t at_most) {
  const size_t stride = std::max<size_t>(1, (indices.size() + at_most - 1) / at_most);
  std::vector<int> out;
  for (size_t k = 0; k < indices.size(); k += stride) out.push_back(indices[k]);
  return out;
}

struct ExtractedPlane {
  Vec3 normal;
  double offset;
  int inliers;
};

// Sequential RANSAC over the boundary points, with local optimisation
// (LO-RANSAC: a triple from a thin rim band is tilted by up to the band's
// width over the rim's span, which costs a large flat rim many inliers
// against a compact side patch; the least-squares plane of its inliers is
// not) and preemptive scoring (a hypothesis is counted on a small sample
// first, on the larger one only if it can compete).
//
// Two modes:
//  - kFresh (the paper): the best plane among the points no plane explains
//    yet; its inliers are then explained.
//  - kCut: the best plane among all boundary points that has the cloud on
//    one side (the cloud was cut there) and is not one already found, i.e.
//    does not share most of its inliers with one. Points are shared
//    because a cuboid's or prism's top rim also lies on the face planes,
//    which are found first and would otherwise explain the rim away; and
//    the side test keeps out the many planes through curved claw outlines
//    that cut through the cloud.
class PlaneExtractor {
 public:
  enum class Mode { kFresh, kCut };

  PlaneExtractor(const std::vector<Vec3>& points, const std::vector<Vec3>& cloud,
                 const VirtualFrameConfig& config, int min_inliers, std::optional<Vec3> hint)
      : points_(points),
        config_(config),
        min_inliers_(min_inliers),
        hint_(hint),
        rng_(config.seed),
        explained_(points.size(), 0) {
    for (size_t i = 0; i < points.size(); ++i) all_.push_back(static_cast<int>(i));
    all_scoring_ = Pack(Strided(all_, kScoringPoints));
    std::vector<Vec3> side;
    const size_t stride =
        std::max<size_t>(1, (cloud.size() + kSideSamplePoints - 1) / kSideSamplePoints);
    for (size_t i = 0; i < cloud.size(); i += stride) side.push_back(cloud[i]);
    // Shuffled, so that a plane through the cloud meets points on both of
    // its sides within the first few and is dropped early.
    for (size_t i = side.size(); i > 1; --i) std::swap(side[i - 1], side[rng_() % i]);
    side_sample_ = Pack(side);
    side_limit_ = static_cast<int>(kStrayFraction * static_cast<double>(side.size()));
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
  void MakeSeeds(const std::optional<Vec3>& hint) {
    const size_t n = points_.size();
    const size_t k = std::min(n, std::max<size_t>(kSeedMinPoints, n / kSeedFraction));
    std::vector<std::pair<double, int>> heights(n);
    std::vector<Vec3> dirs;
    if (hint) {
      dirs.push_back(*hint);
      const Vec3 u = hint->unitOrthogonal(), v = hint->cross(u);
      for (int i = 0; i < 6; ++i) {
        const double a = M_PI / 3 * i;
        dirs.push_back((*hint + std::tan(kMaxRefineAngleRad) * (std::cos(a) * u + std::sin(a) * v))
                           .normalized());
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
      if (FitPlane(points_, top, &normal, &offset)) seeds_.push_back({normal, offset});
    }
  }

  const std::vector<ExtractedPlane>& planes() const { return planes_; }
  ExtractedPlane& mutable_plane(size_t k) { return planes_[k]; }

  /// Adds the next plane; false when there is none with enough inliers.
  bool FindNext(Mode mode) {
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
    const double threshold = config_.plane_distance_m;
    const double log_miss = std::log(1.0 - config_.ransac_confidence);
    const double pre_scale =
        static_cast<double>(preemptive.size()) / static_cast<double>(scoring.size());
    const double min_score =
        min_inliers_ * static_cast<double>(scoring.size()) / static_cast<double>(pool.size());

    int best_score = static_cast<int>(std::ceil(min_score)) - 1;
    bool found = false;
    Vec3 best_normal = Vec3::UnitZ();
    double best_offset = 0.0;
    int needed = config_.max_ransac_iterations;
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
      if (cut && !OneSided(n, d, 2.0 * config_.extreme_band_m)) continue;
      int score = scoring.Count(n, d, threshold);
      // (No duplicate test yet: a seed or triple leaning over a face's top
      // edge shares most points with that face until its refit levels it.)
      if (score < floor) continue;
      for (int round = 0; round < 2; ++round) {
        scoring.Within(n, d, threshold, &support);
        for (int& k : support) k = scoring.index[static_cast<size_t>(k)];
        Vec3 n_ls;
        double d_ls;
        if (!FitPlane(points_, support, &n_ls, &d_ls)) break;
        const int score_ls = scoring.Count(n_ls, d_ls, threshold);
        if (score_ls <= score) break;
        n = n_ls, d = d_ls, score = score_ls;
      }
      if (score <= best_score) continue;
      if (cut && (!OneSided(n, d, config_.extreme_band_m) || Duplicate(n, d))) continue;
      best_score = score;
      best_normal = n;
      best_offset = d;
      found = true;
      // Stop once a triple of this plane's points would have been drawn
      // with the configured confidence.
      const double w = static_cast<double>(score) / static_cast<double>(scoring.size());
      const double p_all = w * w * w;
      needed =
          p_all >= 1.0
              ? std::max(0, it + 1 - n_seeds)
              : static_cast<int>(std::min<double>(config_.max_ransac_iterations,
                                                  std::ceil(log_miss / std::log(1.0 - p_all))));
    }
    if (!found) return false;

    std::vector<int> inliers = Inliers(points_, pool, best_normal, best_offset, threshold);
    Vec3 n;
    double d;
    if (FitPlane(points_, inliers, &n, &d) &&
        !(cut && (!OneSided(n, d, config_.extreme_band_m) || Duplicate(n, d)))) {
      std::vector<int> refit = Inliers(points_, pool, n, d, threshold);
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

 private:
  // Points packed as float arrays (the counting loops vectorise), with
  // their indices into points_.
  struct Packed {
    std::vector<float> x, y, z;
    std::vector<int> index;
    size_t size() const { return x.size(); }
    int Count(const Vec3& n, double d, double threshold) const {
      const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                  nz = static_cast<float>(n.z()), df = static_cast<float>(d),
                  t = static_cast<float>(threshold);
      int count = 0;
      for (size_t k = 0; k < x.size(); ++k) {
        count += std::abs(nx * x[k] + ny * y[k] + nz * z[k] - df) <= t;
      }
      return count;
    }
    // Positions (into this pack) of the points within the threshold.
    void Within(const Vec3& n, double d, double threshold, std::vector<int>* out) const {
      out->clear();
      const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                  nz = static_cast<float>(n.z()), df = static_cast<float>(d),
                  t = static_cast<float>(threshold);
      for (size_t k = 0; k < x.size(); ++k) {
        if (std::abs(nx * x[k] + ny * y[k] + nz * z[k] - df) <= t)
          out->push_back(static_cast<int>(k));
      }
    }
  };

  Packed Pack(const std::vector<int>& indices) const {
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
  static Packed Pack(const std::vector<Vec3>& points) {
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
  bool OneSided(const Vec3& n, double d, double band) const {
    const float nx = static_cast<float>(n.x()), ny = static_cast<float>(n.y()),
                nz = static_cast<float>(n.z()), df = static_cast<float>(d),
                bf = static_cast<float>(band);
    int above = 0, below = 0;
    // Blocks of 16 between the early-exit checks, so the loop vectorises.
    constexpr size_t kBlock = 16;
    const size_t n_points = side_sample_.size();
    for (size_t start = 0; start < n_points; start += kBlock) {
      const size_t end = std::min(n_points, start + kBlock);
      for (size_t k = start; k < end; ++k) {
        const float h =
            nx * side_sample_.x[k] + ny * side_sample_.y[k] + nz * side_sample_.z[k] - df;
        above += h > bf;
        below += h < -bf;
      }
      if (above > side_limit_ && below > side_limit_) return false;
    }
    return true;
  }

  // True if more than kMaxSharedFraction of the plane's inliers (in the
  // scoring sample) are inliers of one plane already found.
  bool Duplicate(const Vec3& n, double d) const {
    if (planes_.empty()) return false;
    all_scoring_.Within(n, d, config_.plane_distance_m, &scratch_);
    for (const std::vector<uint8_t>& mask : masks_) {
      int shared = 0;
      for (int k : scratch_) shared += mask[static_cast<size_t>(k)];
      if (shared > kMaxSharedFraction * static_cast<double>(scratch_.size())) return true;
    }
    return false;
  }

  const std::vector<Vec3>& points_;
  const VirtualFrameConfig& config_;
  const int min_inliers_;
  const std::optional<Vec3> hint_;
  std::mt19937_64 rng_;
  std::vector<int> all_;
  Packed all_scoring_;
  Packed side_sample_;
  int side_limit_{0};
  std::vector<char> explained_;
  std::vector<ExtractedPlane> planes_;
  std::vector<std::vector<uint8_t>> masks_;  // inliers among all_scoring_
  mutable std::vector<int> scratch_;
  std::vector<std::pair<Vec3, double>> seeds_;  // cut-mode seed planes
};

// Number of boundary points within `band` of the highest one along `dir`
// (the third highest, so that two strays cannot hold the plane).
int CountAtTop(const std::vector<Vec3>& boundary, const Vec3& dir, double band,
               std::vector<double>* heights) {
  heights->resize(boundary.size());
  double h1 = -std::numeric_limits<double>::infinity(), h2 = h1, h3 = h1;
  for (size_t i = 0; i < boundary.size(); ++i) {
    const double h = dir.dot(boundary[i]);
    (*heights)[i] = h;
    if (h > h1) {
      h3 = h2, h2 = h1, h1 = h;
    } else if (h > h2) {
      h3 = h2, h2 = h;
    } else if (h > h3) {
      h3 = h;
    }
  }
  int count = 0;
  for (double h : *heights) count += h >= h3 - band;
  return count;
}

// Refits a cut to the rim it touches: the direction, within
// kMaxRefineAngleRad of the cut's empty side `empty`, along which the most
// boundary points lie within plane_distance of the top (coarse-to-fine
// search), then a least-squares plane through those points. RANSAC's
// plane can lean on a claw hole's side; the rim is what was cut level.
void RefineCut(const std::vector<Vec3>& boundary, double plane_distance, const Vec3& empty,
               ExtractedPlane* plane) {
  std::vector<double> heights;
  Vec3 best = empty;
  int best_count = CountAtTop(boundary, best, plane_distance, &heights);
  const double steps[] = {kMaxRefineAngleRad / 3, kMaxRefineAngleRad / 9, kMaxRefineAngleRad / 27};
  for (double step : steps) {
    const Vec3 centre = best;
    const Vec3 u = centre.unitOrthogonal();
    const Vec3 v = centre.cross(u);
    for (int i = -3; i <= 3; ++i) {
      for (int j = -3; j <= 3; ++j) {
        if (i == 0 && j == 0) continue;
        const Vec3 dir = (centre + std::tan(i * step) * u + std::tan(j * step) * v).normalized();
        if (dir.dot(empty) < std::cos(kMaxRefineAngleRad)) continue;
        const int count = CountAtTop(boundary, dir, plane_distance, &heights);
        if (count > best_count) best_count = count, best = dir;
      }
    }
  }
  CountAtTop(boundary, best, plane_distance, &heights);
  double top = -std::numeric_limits<double>::infinity();
  for (double h : heights) top = std::max(top, h);
  std::vector<int> rim;
  for (size_t i = 0; i < boundary.size(); ++i) {
    if (heights[i] >= top - 2.0 * plane_distance) rim.push_back(static_cast<int>(i));
  }
  Vec3 n;
  double d;
  if (!FitPlane(boundary, rim, &n, &d)) return;
  if (n.dot(empty) < std::cos(kMaxRefineAngleRad) && -n.dot(empty) < std::cos(kMaxRefineAngleRad))
    return;
  if (n.dot(plane->normal) < 0) n = -n, d = -d;
  plane->normal = n;
  plane->offset = d;
}

// Distance from `centroid` to the line through the centre of the plane's
// rim (its boundary inliers) along its normal, in units of the rim's RMS
// radius.
double AxisOffset(const std::vector<Vec3>& boundary, const ExtractedPlane& plane, double threshold,
                  const Vec3& centroid) {
  Vec3 centre = Vec3::Zero();
  int count = 0;
  for (const Vec3& b : boundary) {
    if (std::abs(plane.normal.dot(b) - plane.offset) <= threshold) centre += b, ++count;
  }
  if (count == 0) return std::numeric_limits<double>::infinity();
  centre /= count;
  double radius2 = 0.0;
  for (const Vec3& b : boundary) {
    if (std::abs(plane.normal.dot(b) - plane.offset) <= threshold) {
      radius2 += (b - centre).cross(plane.normal).squaredNorm();
    }
  }
  const double radius = std::sqrt(radius2 / count);
  return (centroid - centre).cross(plane.normal).norm() / std::max(radius, 1e-9);
}

// How the cloud sits against a plane: the fraction of its points on the
// plane that have a boundary point nearby (a missing surface: ~1; a face or
// a section through a wall: low), and how many points lie beyond it on
// either side (none on one side: the cloud was cut there).
struct PlaneStats {
  double open_fraction{1.0};
  int above{0};  // points with n . p > offset + band
  int below{0};  // points with n . p < offset - band
};

// The cloud as float arrays, for the passes over all of it.
struct PackedCloud {
  explicit PackedCloud(const std::vector<Vec3>& cloud) {
    x.reserve(cloud.size()), y.reserve(cloud.size()), z.reserve(cloud.size());
    for (const Vec3& p : cloud) {
      x.push_back(static_cast<float>(p.x()));
      y.push_back(static_cast<float>(p.y()));
      z.push_back(static_cast<float>(p.z()));
    }
  }
  std::vector<float> x, y, z;
};

PlaneStats MeasurePlane(const PackedCloud& cloud, const NearGrid& boundary_grid, const Vec3& normal,
                        double offset, double threshold, double band) {
  const float nx = static_cast<float>(normal.x()), ny = static_cast<float>(normal.y()),
              nz = static_cast<float>(normal.z()), d = static_cast<float>(offset),
              t = static_cast<float>(threshold), b = static_cast<float>(band);
  const size_t n = cloud.x.size();
  PlaneStats stats;
  int on_plane = 0;
  for (size_t i = 0; i < n; ++i) {
    const float h = nx * cloud.x[i] + ny * cloud.y[i] + nz * cloud.z[i] - d;
    stats.above += h > b;
    stats.below += h < -b;
    on_plane += std::abs(h) <= t;
  }
  if (on_plane < kMinOpenSupport) return stats;
  // Every stride-th point of the support is tested against the boundary.
  const int stride = std::max(1, on_plane / kOpenSamples);
  int seen = 0, tested = 0, rim = 0;
  for (size_t i = 0; i < n; ++i) {
    const float h = nx * cloud.x[i] + ny * cloud.y[i] + nz * cloud.z[i] - d;
    if (std::abs(h) > t || seen++ % stride != 0) continue;
    ++tested;
    rim += boundary_grid.AnyWithin(Vec3(cloud.x[i], cloud.y[i], cloud.z[i]));
  }
  stats.open_fraction = static_cast<double>(rim) / tested;
  return stats;
}

double Quantile(std::vector<double> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

// Convex hull (counter-clockwise, Andrew's monotone chain) of the lowest and
// highest point of each of `columns` x-columns plus the x extremes: O(n)
// instead of sorting every point, exact to within a column's width.
std::vector<Vec2> ApproxHull(const std::vector<Vec2>& q, int columns) {
  double x_lo = q[0].x(), x_hi = q[0].x();
  size_t i_lo = 0, i_hi = 0;
  for (size_t i = 1; i < q.size(); ++i) {
    if (q[i].x() < x_lo) x_lo = q[i].x(), i_lo = i;
    if (q[i].x() > x_hi) x_hi = q[i].x(), i_hi = i;
  }
  const double width = std::max(x_hi - x_lo, 1e-12);
  std::vector<int> lowest(static_cast<size_t>(columns), -1),
      highest(static_cast<size_t>(columns), -1);
  for (size_t i = 0; i < q.size(); ++i) {
    const int c = std::min(columns - 1, static_cast<int>((q[i].x() - x_lo) / width * columns));
    int& lo = lowest[static_cast<size_t>(c)];
    int& hi = highest[static_cast<size_t>(c)];
    if (lo < 0 || q[i].y() < q[static_cast<size_t>(lo)].y()) lo = static_cast<int>(i);
    if (hi < 0 || q[i].y() > q[static_cast<size_t>(hi)].y()) hi = static_cast<int>(i);
  }
  std::vector<Vec2> pts = {q[i_lo], q[i_hi]};
  for (int c = 0; c < columns; ++c) {
    if (lowest[static_cast<size_t>(c)] >= 0)
      pts.push_back(q[static_cast<size_t>(lowest[static_cast<size_t>(c)])]);
    if (highest[static_cast<size_t>(c)] >= 0)
      pts.push_back(q[static_cast<size_t>(highest[static_cast<size_t>(c)])]);
  }
  return ConvexHull2d(&pts);
}

struct Rect2 {
  Vec2 axis{1, 0};  // unit, along the longer side
  Vec2 centre{0, 0};
};

// Minimum-area enclosing rectangle: one of its sides lies on a hull edge
// (the theorem behind rotating calipers); with at most 2 * hull_columns + 2
// hull points, every edge direction is simply tried.
Rect2 MinAreaRect(const std::vector<Vec2>& hull) {
  std::vector<Vec2> dirs;
  const size_t h = hull.size();
  const size_t edges = h >= 3 ? h : (h == 2 ? 1 : 0);
  for (size_t i = 0; i < edges; ++i) {
    const Vec2 e = hull[(i + 1) % h] - hull[i];
    if (e.norm() > 0) dirs.push_back(e.normalized());
  }
  if (dirs.empty()) dirs.push_back(Vec2(1, 0));
  double best_area = std::numeric_limits<double>::infinity();
  Rect2 best;
  for (const Vec2& e : dirs) {
    const Vec2 n(-e.y(), e.x());
    double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
    for (const Vec2& p : hull) {
      a0 = std::min(a0, e.dot(p)), a1 = std::max(a1, e.dot(p));
      b0 = std::min(b0, n.dot(p)), b1 = std::max(b1, n.dot(p));
    }
    const double area = (a1 - a0) * (b1 - b0);
    if (area < best_area) {
      best_area = area;
      best.centre = 0.5 * (a0 + a1) * e + 0.5 * (b0 + b1) * n;
      best.axis = (a1 - a0) >= (b1 - b0) ? e : n;
    }
  }
  return best;
}

}  // namespace

void VirtualFrameConfig::Validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("VirtualFrameConfig: " + what);
  };
  auto positive = [&](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) fail(std::string(name) + " must be finite and > 0");
  };
  positive(plane_distance_m, "plane_distance_m");
  positive(open_support_radius_m, "open_support_radius_m");
  positive(extreme_band_m, "extreme_band_m");
  if (max_planes < 1) fail("max_planes must be >= 1");
  if (min_plane_inliers < 3) fail("min_plane_inliers must be >= 3");
  if (!(min_plane_fraction >= 0.0 && min_plane_fraction < 1.0))
    fail("min_plane_fraction must be in [0, 1)");
  if (max_ransac_iterations < 1) fail("max_ransac_iterations must be >= 1");
  if (!(ransac_confidence > 0.0 && ransac_confidence < 1.0))
    fail("ransac_confidence must be in (0, 1)");
  if (!(min_open_fraction >= 0.0 && min_open_fraction <= 1.0))
    fail("min_open_fraction must be in [0, 1]");
  if (!(open_fraction_tie >= 0.0 && open_fraction_tie <= 1.0))
    fail("open_fraction_tie must be in [0, 1]");
  if (!(axis_offset_tie >= 0.0) || !std::isfinite(axis_offset_tie))
    fail("axis_offset_tie must be finite and >= 0");
  if (!(eq4_tie_tolerance >= 0.0) || !std::isfinite(eq4_tie_tolerance))
    fail("eq4_tie_tolerance must be finite and >= 0");
  if (!(hint_max_angle_rad > 0.0 && hint_max_angle_rad <= M_PI / 2))
    fail("hint_max_angle_rad must be in (0, pi/2]");
  if (hull_columns < 2) fail("hull_columns must be >= 2");
}

std::optional<VirtualFrame> EstimateVirtualFrame(const PointList& cloud_in,
                                                 const PointList& boundary_in,
                                                 const VirtualFrameConfig& config,
                                                 const Eigen::Vector3d* up_hint,
                                                 std::string* failure_reason,
                                                 std::vector<BoundaryPlane>* planes_out) {
  config.Validate();
  if (planes_out) planes_out->clear();
  auto fail = [&](const std::string& why) -> std::optional<VirtualFrame> {
    if (failure_reason) *failure_reason = why;
    return std::nullopt;
  };
  const std::vector<Vec3> cloud = FinitePoints(cloud_in);
  const std::vector<Vec3> boundary = FinitePoints(boundary_in);
  if (cloud.empty()) return fail("virtual frame: the cloud has no finite point");
  const int min_inliers = std::max(
      config.min_plane_inliers, static_cast<int>(std::ceil(config.min_plane_fraction *
                                                           static_cast<double>(boundary.size()))));
  if (static_cast<int>(boundary.size()) < min_inliers) {
    return fail("virtual frame: " + std::to_string(boundary.size()) +
                " finite boundary points, a plane needs " + std::to_string(min_inliers));
  }
  std::optional<Vec3> hint;
  if (up_hint && up_hint->allFinite() && up_hint->norm() > 0) hint = up_hint->normalized();
  const double hint_min_cos = std::cos(config.hint_max_angle_rad);
  auto in_hint_cone = [&](const Vec3& n) {
    return !hint || std::abs(n.dot(*hint)) >= hint_min_cos;
  };
  const NearGrid grid(boundary, config.open_support_radius_m);
  const PackedCloud packed_cloud(cloud);
  const int stray_limit = static_cast<int>(kStrayFraction * static_cast<double>(cloud.size()));

  // 1.-2. The missing-surface plane.
  PlaneExtractor extractor(boundary, cloud, config, min_inliers, hint);
  std::vector<PlaneStats> stats;
  auto measure_all = [&] {
    for (size_t k = stats.size(); k < extractor.planes().size(); ++k) {
      const ExtractedPlane& p = extractor.planes()[k];
      stats.push_back(MeasurePlane(packed_cloud, grid, p.normal, p.offset, config.plane_distance_m,
                                   config.extreme_band_m));
    }
  };
  std::vector<size_t> candidates;
  std::vector<double> axis_offset(2 * static_cast<size_t>(config.max_planes), -1.0);
  bool use_eq4_of_candidates = false;
  if (config.prefer_open_planes) {
    // Open cuts refitted to their rims; the most open; the one square to
    // the symmetry axis; Eq. 4 among those still tied; the inlier count.
    // (Eq. 4 alone fails on an ellipsoid: the claw planes on its two
    // flatter sides are orthogonal to the one on its end.)
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& p : cloud) centroid += p;
    centroid /= static_cast<double>(cloud.size());
    std::vector<char> merged;
    while (static_cast<int>(extractor.planes().size()) < config.max_planes &&
           extractor.FindNext(PlaneExtractor::Mode::kCut)) {
      measure_all();
      const size_t k = stats.size() - 1;
      merged.push_back(0);
      // Only planes that could be the top are worth the refit.
      if (stats[k].open_fraction < kMinRefineOpenFraction) continue;
      ExtractedPlane& p = extractor.mutable_plane(k);
      const bool empty_above = stats[k].above <= stats[k].below;
      RefineCut(boundary, config.plane_distance_m, empty_above ? p.normal : Vec3(-p.normal), &p);
      stats[k] = MeasurePlane(packed_cloud, grid, p.normal, p.offset, config.plane_distance_m,
                              config.extreme_band_m);
      // Two refits that met on the same rim are one plane.
      for (size_t i = 0; i < k && !merged[k]; ++i) {
        const ExtractedPlane& a = extractor.planes()[i];
        const double c = a.normal.dot(p.normal);
        merged[k] =
            !merged[i] && std::abs(c) >= std::cos(kMaxRefineAngleRad / 2) &&
            std::abs(a.offset - (c > 0 ? p.offset : -p.offset)) <= 2.0 * config.plane_distance_m;
      }
      // A clean cut square to the axis is the top: no other plane could
      // beat it below, so the search stops (saving the rounds after it).
      if (!merged[k] && std::min(stats[k].above, stats[k].below) <= stray_limit &&
          stats[k].open_fraction >= 1.0 - config.open_fraction_tie && in_hint_cone(p.normal)) {
        axis_offset[k] = AxisOffset(boundary, p, config.plane_distance_m, centroid);
        if (axis_offset[k] <= config.axis_offset_tie) break;
      }
    }
    for (size_t k = 0; k < stats.size(); ++k) {
      if (!merged[k] && std::min(stats[k].above, stats[k].below) <= stray_limit &&
          stats[k].open_fraction >= config.min_open_fraction &&
          in_hint_cone(extractor.planes()[k].normal)) {
        candidates.push_back(k);
      }
    }
    // The cleanest cut: the top was cut by a plane (and its plane refitted
    // to the rim), while a claw hole's outline is planar only on a planar
    // face, which is no cut, and close to a plane on a curved one (a
    // sphere: 0.7-0.8 open).
    double most_open = 0.0;
    for (size_t k : candidates) most_open = std::max(most_open, stats[k].open_fraction);
    std::vector<size_t> kept;
    for (size_t k : candidates) {
      if (stats[k].open_fraction >= most_open - config.open_fraction_tie) kept.push_back(k);
    }
    candidates = std::move(kept);
    // Then the one square to the symmetry axis: the normal through the
    // cut's centre passes through the cloud's centroid. (A plane that only
    // touches the rim from aside is as open, but tilted off the axis.)
    double best_offset = std::numeric_limits<double>::infinity();
    for (size_t k : candidates) {
      axis_offset[k] =
          AxisOffset(boundary, extractor.planes()[k], config.plane_distance_m, centroid);
      best_offset = std::min(best_offset, axis_offset[k]);
    }
    kept.clear();
    for (size_t k : candidates) {
      if (axis_offset[k] <= best_offset + config.axis_offset_tie) kept.push_back(k);
    }
    candidates = std::move(kept);
    use_eq4_of_candidates = true;
  }
  if (candidates.empty()) {
    // The paper: planes each taking the points no earlier one explains,
    // Eq. 4 over all of them.
    const size_t first = extractor.planes().size();
    while (static_cast<int>(extractor.planes().size() - first) < config.max_planes &&
           extractor.FindNext(PlaneExtractor::Mode::kFresh)) {
    }
    measure_all();
    for (size_t k = first; k < extractor.planes().size(); ++k) {
      if (in_hint_cone(extractor.planes()[k].normal)) candidates.push_back(k);
    }
    if (candidates.empty()) {
      for (size_t k = first; k < extractor.planes().size(); ++k) candidates.push_back(k);
    }
    use_eq4_of_candidates = false;
  }
  const std::vector<ExtractedPlane>& extracted = extractor.planes();
  if (candidates.empty()) {
    return fail("virtual frame: no plane with " + std::to_string(min_inliers) + " of the " +
                std::to_string(boundary.size()) + " boundary points within " +
                std::to_string(config.plane_distance_m) + " m");
  }
  std::vector<BoundaryPlane> planes(extracted.size());
  for (size_t k = 0; k < planes.size(); ++k) {
    planes[k].normal = extracted[k].normal;
    planes[k].offset = extracted[k].offset;
    planes[k].inliers = extracted[k].inliers;
    planes[k].open_fraction = stats[k].open_fraction;
    planes[k].cut = std::min(stats[k].above, stats[k].below) <= stray_limit;
    planes[k].axis_offset = axis_offset[k];
    for (size_t i = 0; i < planes.size(); ++i) {
      if (i != k) planes[k].eq4_sum += std::abs(extracted[k].normal.dot(extracted[i].normal));
    }
  }
  std::vector<double> sums(planes.size());
  for (size_t k : candidates) {
    if (!use_eq4_of_candidates) {
      sums[k] = planes[k].eq4_sum;
      continue;
    }
    for (size_t i : candidates) {
      if (i != k) sums[k] += std::abs(planes[k].normal.dot(planes[i].normal));
    }
  }
  double min_sum = std::numeric_limits<double>::infinity();
  for (size_t k : candidates) min_sum = std::min(min_sum, sums[k]);
  size_t chosen = candidates.front();
  int chosen_inliers = -1;
  for (size_t k : candidates) {
    if (sums[k] <= min_sum + config.eq4_tie_tolerance && planes[k].inliers > chosen_inliers) {
      chosen = k;
      chosen_inliers = planes[k].inliers;
    }
  }
  planes[chosen].chosen = true;
  // Least-squares refit on every boundary point near the chosen plane.
  Vec3 n = planes[chosen].normal;
  double d = planes[chosen].offset;
  std::vector<int> all_boundary(boundary.size());
  for (size_t i = 0; i < boundary.size(); ++i) all_boundary[i] = static_cast<int>(i);
  for (int round = 0; round < 2; ++round) {
    Vec3 n_ls;
    double d_ls;
    if (!FitPlane(boundary, Inliers(boundary, all_boundary, n, d, config.plane_distance_m), &n_ls,
                  &d_ls)) {
      break;
    }
    if (n_ls.dot(n) < 0) n_ls = -n_ls, d_ls = -d_ls;
    n = n_ls, d = d_ls;
  }

  // 3. The sign of z: towards the missing surface.
  std::vector<double> heights(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) heights[i] = n.dot(cloud[i]);
  double sign = 1.0;
  const PlaneStats& st = stats[chosen];
  // (The refit keeps the normal's sign, so above and below still apply.)
  const bool empty_above = st.above <= stray_limit;
  const bool empty_below = st.below <= stray_limit;
  if (hint && std::abs(n.dot(*hint)) > 1e-6) {
    sign = n.dot(*hint) > 0 ? 1.0 : -1.0;
  } else if (empty_above != empty_below) {
    // The cloud lies on one side of the plane: it was cut there.
    sign = empty_above ? 1.0 : -1.0;
  } else {
    // Else the end of the cloud the boundary crowds at (the open rim).
    const double lo = Quantile(heights, kStrayFraction);
    const double hi = Quantile(heights, 1.0 - kStrayFraction);
    int near_hi = 0, near_lo = 0;
    for (const Vec3& b : boundary) {
      const double h = n.dot(b);
      near_hi += h >= hi - config.extreme_band_m;
      near_lo += h <= lo + config.extreme_band_m;
    }
    if (near_hi != near_lo) {
      sign = near_hi > near_lo ? 1.0 : -1.0;
    } else {
      double mean = 0.0;
      for (double h : heights) mean += h;
      sign = d >= mean / static_cast<double>(heights.size()) ? 1.0 : -1.0;
    }
  }
  const Vec3 z = sign * n;

  // 4. x, y from the minimum-area rectangle of the projected cloud.
  const Vec3 seed_axis = std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = (seed_axis - z * z.dot(seed_axis)).normalized();
  const Vec3 v = z.cross(u);
  std::vector<Vec2> projected(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) projected[i] = Vec2(u.dot(cloud[i]), v.dot(cloud[i]));
  const Rect2 rect = MinAreaRect(ApproxHull(projected, config.hull_columns));
  Vec3 x = rect.axis.x() * u + rect.axis.y() * v;
  int largest = 0;
  x.cwiseAbs().maxCoeff(&largest);
  if (x[largest] < 0) x = -x;
  const Vec3 y = z.cross(x);

  // 5. Origin: rectangle centre, at the cloud's lowest z.
  const double z_min = sign > 0 ? *std::min_element(heights.begin(), heights.end())
                                : -*std::max_element(heights.begin(), heights.end());
  VirtualFrame frame;
  frame.T_in_V.linear().col(0) = x;
  frame.T_in_V.linear().col(1) = y;
  frame.T_in_V.linear().col(2) = z;
  frame.T_in_V.translation() = rect.centre.x() * u + rect.centre.y() * v + z_min * z;
  const Eigen::Isometry3d T_V_in = frame.T_in_V.inverse();
  Eigen::AlignedBox3d box;
  for (const Vec3& p : cloud) box.extend(T_V_in * p);
  frame.min_V = box.min().cast<float>();
  frame.max_V = box.max().cast<float>();
  if (planes_out) *planes_out = std::move(planes);
  return frame;
}

PointList ToVirtualFrame(const PointList& points_in, const VirtualFrame& frame) {
  const Eigen::Isometry3f T_V_in = frame.T_in_V.inverse().cast<float>();
  PointList out;
  out.reserve(points_in.size());
  for (const Eigen::Vector3f& p : points_in) out.push_back(T_V_in * p);
  return out;
}

}  // namespace graspfill::repair
