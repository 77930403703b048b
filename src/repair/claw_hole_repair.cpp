#include "graspfill/repair/claw_hole_repair.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

// Costs measured on the 2-core dev machine (Open3D 0.16.1, one thread,
// other builds running, so wall times vary by up to 2x; protocol clouds):
//  - kLocalFit (the default), 3 holes (top-straight grasp), ~50k points,
//    shared index, CPU time: cylinder 6-8 ms (one height field per hole),
//    cuboid 13-18 ms (its holes at 120 and 240 degrees reach the vertical
//    edges: normals of 500 points and two sheets), sphere 27-31 ms (quadric
//    and 13k new points). KD-tree queries dominate what is left; the gap
//    test, once a KD query per candidate and half of the time, now looks
//    up a grid over the hole.
//  - Poisson of a whole 50k cloud with normals: 720-1040 ms at depth 6,
//    1.9-3.4 s at depth 7. The paper's settings (all side points of a 38k
//    cloud, depth 6, scale 4, normals estimated): 0.63-0.92 s. The
//    Poisson-only baseline (depth 7, scale 2): 1.1-2.2 s.
//  - Poisson of one hole's support (~3.6k points): 290, 360 and 690-800 ms
//    at depth 4, 5 and 6; 3 holes with their normals: 2.4-3.9 s. Open3D
//    keeps PoissonRecon's full_depth = 5 (a dense 33^3 system) and its
//    B-spline integrator setup whatever the input, so a small local problem
//    costs nearly as much as a large one: no local Poisson meets a 100 ms
//    budget, hence the explicit local surfaces by default.
//  - PCA normals of 50k points (Open3D EstimateNormals, knn 16): 140-190 ms;
//    OrientNormalsConsistentTangentPlane(16) on top: 14-23 s (an MST over
//    the whole cloud), hence the orientation away from the centroid here.
// Open3D's Poisson with n_threads = 1 gives the same mesh run after run
// (claw_hole_repair_test checks the fill is deterministic), and its mesh
// winds outwards as its input normals point (checked on a cylinder patch).
// With OMP_THREAD_LIMIT=1, PoissonRecon prints "getValue assumes leaf node"
// warnings to stderr; the mesh is the same as without the limit.

namespace graspfill::repair {
namespace {

using Box = Eigen::AlignedBox3f;

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void CheckFinite(const PointList& points, const char* what) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument(std::string(what) + ": non-finite coordinate at index " +
                                  std::to_string(i));
    }
  }
}

void CheckInputs(const PointList& points, const std::vector<Eigen::Vector3f>* normals,
                 const NeighborIndex* index, const char* what) {
  CheckFinite(points, what);
  if (normals != nullptr) {
    Require(normals->size() == points.size(),
            std::string(what) + ": " + std::to_string(normals->size()) + " normals for " +
                std::to_string(points.size()) + " points");
    CheckFinite(*normals, what);
  }
  if (index != nullptr) {
    Require(&index->points() == &points,
            std::string(what) + ": the neighbour index must be built over the same cloud");
  }
}

uint64_t MixSeed(uint64_t seed, uint64_t stream) {
  // SplitMix64 of the pair: neighbouring streams look independent.
  uint64_t x = seed ^ (stream * 0x9e3779b97f4a7c15ULL + 0x632be59bd9b4e019ULL);
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from 53 bits, written out so that a seed gives the same
// numbers with every standard library.
class Uniform01 {
 public:
  explicit Uniform01(uint64_t seed) : engine_(seed) {}
  double operator()() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 engine_;
};

// Sampling of the cloud around some of its points: D (mean distance to the
// nearest neighbour) and the surface density. The density comes from the
// k-th neighbour radius (pi r_k^2 rho ~ Gamma(k, 1) on a surface sampled at
// rho), so it holds for random and for grid-like (TSDF) samplings alike,
// where D alone would be off by a factor that depends on the pattern.
struct Spacing {
  double mean_nn_m{0.0};
  double density_per_m2{0.0};
};

Spacing EstimateSpacing(const NeighborIndex& index, const std::vector<int>& subset,
                        size_t max_queries) {
  constexpr int kK = 8;
  Spacing out;
  if (subset.empty()) return out;
  const size_t stride = std::max<size_t>(1, subset.size() / max_queries);
  std::vector<int> nn;
  std::vector<double> d2;
  double nn_sum = 0.0, rk2_sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < subset.size(); i += stride) {
    index.Knn(index.points()[subset[i]], kK + 1, &nn, &d2);
    if (static_cast<int>(d2.size()) < kK + 1) continue;
    nn_sum += std::sqrt(d2[1]);  // d2[0] is the point itself
    rk2_sum += d2[kK];
    ++count;
  }
  if (count == 0 || rk2_sum <= 0.0) return out;
  out.mean_nn_m = nn_sum / count;
  out.density_per_m2 = kK / (M_PI * rk2_sum / count);
  return out;
}

// Least-squares plane of `pts` (PCA): its normal, the eigenvector of the
// covariance's smallest eigenvalue; also the mean and the eigenvalues
// (increasing).
Eigen::Vector3d PlaneOf(const std::vector<Eigen::Vector3d>& pts, Eigen::Vector3d* mean,
                        Eigen::Vector3d* eigenvalues) {
  *mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : pts) *mean += p;
  *mean /= static_cast<double>(std::max<size_t>(1, pts.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : pts) cov += (p - *mean) * (p - *mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  *eigenvalues = eig.eigenvalues();
  return eig.eigenvectors().col(0);
}

// PCA normals of `subset` (knn over the whole cloud), oriented away from
// `centre`: right for the convex-ish objects a claw holds, and cheap, where
// Open3D's consistent tangent-plane orientation takes seconds.
std::vector<Eigen::Vector3f> EstimateNormals(const NeighborIndex& index,
                                             const std::vector<int>& subset, int k,
                                             const Eigen::Vector3f& centre) {
  const PointList& points = index.points();
  std::vector<Eigen::Vector3f> normals(subset.size());
  std::vector<int> nn;
  std::vector<double> d2;
  std::vector<Eigen::Vector3d> near;
  Eigen::Vector3d mean, eigenvalues;
  for (size_t i = 0; i < subset.size(); ++i) {
    const Eigen::Vector3f& p = points[subset[i]];
    index.Knn(p, k, &nn, &d2);
    near.clear();
    for (int j : nn) near.push_back(points[j].cast<double>());
    Eigen::Vector3f n = PlaneOf(near, &mean, &eigenvalues).cast<float>();
    if (n.dot(p - centre) < 0.0f) n = -n;
    normals[i] = n;
  }
  return normals;
}

// Samples already added, hashed on a grid, so that holes whose boxes
// overlap do not fill the same place twice.
class AddedPoints {
 public:
  explicit AddedPoints(double cell_m) : cell_(cell_m) {}
  bool AnyWithin(const Eigen::Vector3f& p, double radius_m) const {
    const int reach = static_cast<int>(std::ceil(radius_m / cell_));
    const Eigen::Vector3i c = Cell(p);
    const float r2 = static_cast<float>(radius_m * radius_m);
    for (int dx = -reach; dx <= reach; ++dx) {
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dz = -reach; dz <= reach; ++dz) {
          const auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const Eigen::Vector3f& q : it->second) {
            if ((q - p).squaredNorm() <= r2) return true;
          }
        }
      }
    }
    return false;
  }
  void Add(const Eigen::Vector3f& p) { cells_[Key(Cell(p))].push_back(p); }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3f& p) const {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell_)),
                           static_cast<int>(std::floor(p.y() / cell_)),
                           static_cast<int>(std::floor(p.z() / cell_)));
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<uint64_t>(v) & 0x1fffffULL; };
    return (u(c.x()) << 42) | (u(c.y()) << 21) | u(c.z());
  }
  double cell_;
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3f>> cells_;
};

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// ---------------------------------------------------------------------------
// The hole's own frame and fill region.

// Origin and normal from the plane of the hole's rim (PCA), n outward, v
// along V's z projected on that plane (the holes stand upright in V), u
// across. The rim, not the support, sets the plane: a hole at a cuboid's
// corner has a support that wraps over the edge, while its rim stays on
// its own face.
struct HoleFrame {
  Eigen::Vector3d origin{Eigen::Vector3d::Zero()};
  Eigen::Vector3d e1{Eigen::Vector3d::UnitX()}, e2{Eigen::Vector3d::UnitY()},
      n{Eigen::Vector3d::UnitZ()};

  Eigen::Vector3d Local(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - origin;
    return {d.dot(e1), d.dot(e2), d.dot(n)};
  }
  Eigen::Vector3d World(double u, double v, double w) const {
    return origin + u * e1 + v * e2 + w * n;
  }
};

HoleFrame MakeHoleFrame(const PointList& rim, const PointList& points,
                        const std::vector<int>& support, const Eigen::Vector3d& outward_hint) {
  std::vector<Eigen::Vector3d> pts;
  for (const Eigen::Vector3f& p : rim) pts.push_back(p.cast<double>());
  HoleFrame f;
  Eigen::Vector3d eigenvalues;
  f.n = PlaneOf(pts, &f.origin, &eigenvalues);
  // A rim too thin to span a plane (a degenerate boundary): the support's.
  if (!(eigenvalues(1) > 1e-4 * eigenvalues(2))) {
    pts.clear();
    for (int i : support) pts.push_back(points[i].cast<double>());
    f.n = PlaneOf(pts, &f.origin, &eigenvalues);
  }
  if (f.n.dot(outward_hint) < 0.0) f.n = -f.n;
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitZ() - f.n.z() * f.n;
  if (e2.norm() < 0.1) e2 = Eigen::Vector3d::UnitX() - f.n.x() * f.n;
  f.e2 = e2.normalized();
  f.e1 = f.e2.cross(f.n);
  return f;
}

// Where a hole's fill may go, in its frame: the rim's (u, v) rectangle
// padded, and a range of heights along n. The paper takes the rim's
// bounding box in V; on a doubly curved surface (sphere, ellipsoid) the
// surface over the hole bulges out of that box (by ~2.5 mm for the
// protocol's holes on the 8 cm sphere), so the rectangle is taken in the
// hole's frame and the height is left free or bounded generously.
struct FillRegion {
  Eigen::Vector3d lo, hi;
  // V's z range of the rim (padded): a side hole's fill must not grow into
  // the missing top (V's +z) however the surface bends.
  double z_lo{-std::numeric_limits<double>::infinity()};
  double z_hi{std::numeric_limits<double>::infinity()};
  bool Contains(const Eigen::Vector3d& local) const {
    return (local.array() >= lo.array()).all() && (local.array() <= hi.array()).all();
  }
  bool InZ(double z) const { return z >= z_lo && z <= z_hi; }
};

// The rim's box in f's local coordinates, padded by `pad` in u and v, with
// V's z range [z_lo, z_hi].
FillRegion RimRegion(const PointList& rim, const HoleFrame& f, double pad, double z_lo,
                     double z_hi) {
  FillRegion r;
  r.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  r.hi = -r.lo;
  for (const Eigen::Vector3f& p : rim) {
    const Eigen::Vector3d l = f.Local(p.cast<double>());
    r.lo = r.lo.cwiseMin(l);
    r.hi = r.hi.cwiseMax(l);
  }
  r.lo.head<2>().array() -= pad;
  r.hi.head<2>().array() += pad;
  r.z_lo = z_lo;
  r.z_hi = z_hi;
  return r;
}

// Decides whether a candidate is new: no cloud point and no point added
// for an earlier hole within `gap_m`. Samples of the same surface are not
// tested against each other: that would thin the fill below the input's
// density (half the points of a random sampling have a neighbour closer
// than D). For a hole, the points that can be that close (the cloud points
// of the support box and the earlier fills) are bucketed on a 2D grid over
// the hole's (u, v) rectangle, so that a test is nine cell lookups instead
// of a KD-tree query (which took about half of the fill's time); a
// candidate off the grid asks the shared index and the earlier fills.
class GapTest {
 public:
  GapTest(const NeighborIndex& index, const AddedPoints* earlier, double gap_m)
      : index_(index), earlier_(earlier), gap_m_(gap_m) {}

  // Grid over (u, v) in [lo, hi] of `frame`: `near` (indices into the
  // cloud) must hold every cloud point of `covered`.
  void BuildGrid(const HoleFrame& frame, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                 const std::vector<int>& near, const Box& covered, const PointList& earlier_fill);
  bool IsNew(const Eigen::Vector3f& p);

 private:
  bool GridHas(const Eigen::Vector3f& p, const Eigen::Vector3d& local) const;

  const NeighborIndex& index_;
  const AddedPoints* earlier_;
  double gap_m_;
  std::vector<int> nn_;
  std::vector<double> d2_;
  // The grid (empty when not built).
  const HoleFrame* frame_{nullptr};
  Box trusted_;  // candidates inside it are decided by the grid alone
  Eigen::Vector2d lo_{0, 0};
  double cell_{1.0};
  int nu_{0}, nv_{0};
  std::vector<int> start_;  // CSR: cell c holds pts_[start_[c], start_[c + 1])
  PointList pts_;
};

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

// ---------------------------------------------------------------------------
// Local surfaces: polynomial height fields and quadrics.

// Up to the 21 monomials of degree 5, on the stack.
using BasisVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 21, 1>;

// w = sum a_ij u^i v^j (i + j <= degree) in the hole's frame; u, v divided
// by `scale` to keep the normal equations well conditioned.
struct HeightField {
  HoleFrame frame;
  double scale{1.0};
  int degree{2};
  BasisVec coeffs;
  double sigma_m{0.0};  ///< robust scale (1.4826 MAD) of the last residuals

  static int NumTerms(int degree) { return (degree + 1) * (degree + 2) / 2; }

  // Monomials (and their u, v derivatives when asked) at (u, v) [m].
  void Basis(double u, double v, BasisVec* f, BasisVec* fu, BasisVec* fv) const {
    const double x = u / scale, y = v / scale;
    double px[8], py[8];
    px[0] = py[0] = 1.0;
    for (int i = 1; i <= degree; ++i) px[i] = px[i - 1] * x, py[i] = py[i - 1] * y;
    f->resize(NumTerms(degree));
    if (fu) fu->resize(f->size());
    if (fv) fv->resize(f->size());
    int t = 0;
    for (int total = 0; total <= degree; ++total) {
      for (int i = total; i >= 0; --i, ++t) {
        const int j = total - i;
        (*f)(t) = px[i] * py[j];
        if (fu) (*fu)(t) = i > 0 ? i * px[i - 1] * py[j] / scale : 0.0;
        if (fv) (*fv)(t) = j > 0 ? j * px[i] * py[j - 1] / scale : 0.0;
      }
    }
  }
  Eigen::Vector3d Point(double u, double v) const {
    BasisVec f;
    Basis(u, v, &f, nullptr, nullptr);
    return frame.World(u, v, f.dot(coeffs));
  }
  // Signed height of p above the sheet along n (outside the object > 0).
  double Above(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d l = frame.Local(p);
    BasisVec f;
    Basis(l.x(), l.y(), &f, nullptr, nullptr);
    return l.z() - f.dot(coeffs);
  }
  // Whether the sheet vouches for a point it made (always).
  bool Holds(const Eigen::Vector3d&) const { return true; }
  // Area element sqrt(1 + h_u^2 + h_v^2) of the height field at (u, v).
  double AreaElement(double u, double v) const {
    BasisVec f, fu, fv;
    Basis(u, v, &f, &fu, &fv);
    const double hu = fu.dot(coeffs), hv = fv.dot(coeffs);
    return std::sqrt(1.0 + hu * hu + hv * hv);
  }
};

// At most `max_count` of `indices`, evenly strided: the fits need ~2000
// points, and their cost then stays flat on dense clouds.
std::vector<int> Thin(const std::vector<int>& indices, size_t max_count) {
  if (indices.size() <= max_count) return indices;
  const size_t stride = (indices.size() + max_count - 1) / max_count;
  std::vector<int> out;
  for (size_t i = 0; i < indices.size(); i += stride) out.push_back(indices[i]);
  return out;
}

// Fits the height field to `support` by iteratively reweighted least
// squares with Tukey's biweight (c = 4.685 sigma, sigma = 1.4826 MAD):
// points of another face past a sharp edge, or across a fold, get weight 0
// instead of bending the surface. The first weights come from the
// residuals to the rim's plane (the frame's), not from a plain least-
// squares fit, which at a corner would split the difference between the
// two faces; the first two iterations fit a plane, the others the full
// degree. Returns false when there are too few points for the degree.
bool FitHeightField(const PointList& points, const std::vector<int>& support,
                    const HoleFrame& frame, int degree, int iterations, double sigma_floor_m,
                    HeightField* hf) {
  const int terms = HeightField::NumTerms(degree);
  const std::vector<int> used = Thin(support, 2000);
  const int m = static_cast<int>(used.size());
  if (m < 3 * terms) return false;
  hf->frame = frame;
  hf->degree = degree;
  Eigen::VectorXd u(m), v(m), w(m);
  double scale = 0.0;
  for (int k = 0; k < m; ++k) {
    const Eigen::Vector3d l = frame.Local(points[used[k]].cast<double>());
    u(k) = l.x();
    v(k) = l.y();
    w(k) = l.z();
    scale = std::max({scale, std::abs(u(k)), std::abs(v(k))});
  }
  hf->scale = scale > 0.0 ? scale : 1.0;
  Eigen::MatrixXd a(m, terms);
  BasisVec f;
  for (int k = 0; k < m; ++k) {
    hf->Basis(u(k), v(k), &f, nullptr, nullptr);
    a.row(k) = f.transpose();
  }
  Eigen::VectorXd weights(m);
  std::vector<double> abs_residual(m);
  const auto reweight = [&](const Eigen::VectorXd& residual) {
    for (int k = 0; k < m; ++k) abs_residual[k] = std::abs(residual(k));
    hf->sigma_m = 1.4826 * Median(abs_residual);
    const double c = 4.685 * std::max(hf->sigma_m, sigma_floor_m);
    for (int k = 0; k < m; ++k) {
      const double r = residual(k) / c;
      weights(k) = std::abs(r) < 1.0 ? (1.0 - r * r) * (1.0 - r * r) : 0.0;
    }
  };
  reweight(w);  // residuals to the rim's plane
  hf->coeffs = Eigen::VectorXd::Zero(terms);
  const int plane_terms = HeightField::NumTerms(std::min(1, degree));
  for (int it = 0; it < iterations; ++it) {
    const int t = it < 2 ? plane_terms : terms;
    const Eigen::MatrixXd aw = a.leftCols(t).array().colwise() * weights.array();
    Eigen::MatrixXd normal = aw.transpose() * a.leftCols(t);
    // A whisper of ridge keeps the solve defined when the weights leave
    // too few points for some monomial.
    normal.diagonal().array() += 1e-12 * (normal.trace() / t + 1.0);
    hf->coeffs.setZero();
    hf->coeffs.head(t) = normal.ldlt().solve(aw.transpose() * w);
    reweight(w - a * hf->coeffs);
  }
  return hf->coeffs.allFinite();
}

// An implicit quadric q . v(y) = 0, v = (y1^2, y2^2, y3^2, y1 y2, y1 y3,
// y2 y3, y1, y2, y3, 1), in coordinates y = (x - mean) / scale. Spheres,
// ellipsoids, cylinders and planes are quadrics, so on those a quadric
// follows a hole of any size exactly, where a polynomial height field over
// a patch spanning ~90 degrees of a sphere sags by ~1 mm.
struct Quadric {
  Eigen::Vector3d mean{Eigen::Vector3d::Zero()};
  double scale{1.0};
  Eigen::Matrix<double, 10, 1> q{Eigen::Matrix<double, 10, 1>::Zero()};
  double sigma_m{0.0};  ///< robust scale of the geometric residuals

  static Eigen::Matrix<double, 10, 1> V(const Eigen::Vector3d& y) {
    Eigen::Matrix<double, 10, 1> v;
    v << y.x() * y.x(), y.y() * y.y(), y.z() * y.z(), y.x() * y.y(), y.x() * y.z(),
        y.y() * y.z(), y.x(), y.y(), y.z(), 1.0;
    return v;
  }
  // d v / d y (3 x 10).
  static Eigen::Matrix<double, 3, 10> J(const Eigen::Vector3d& y) {
    Eigen::Matrix<double, 3, 10> j = Eigen::Matrix<double, 3, 10>::Zero();
    j(0, 0) = 2 * y.x(), j(0, 3) = y.y(), j(0, 4) = y.z(), j(0, 6) = 1;
    j(1, 1) = 2 * y.y(), j(1, 3) = y.x(), j(1, 5) = y.z(), j(1, 7) = 1;
    j(2, 2) = 2 * y.z(), j(2, 4) = y.x(), j(2, 5) = y.y(), j(2, 8) = 1;
    return j;
  }
  // A pair of planes (the rank-2 degenerate quadric) fits the two faces of
  // an edge exactly, but continues each face past the edge and has no
  // gradient along it. Spheres, ellipsoids and cylinders have rank >= 3.
  bool IsPlanePair() const {
    Eigen::Matrix4d m;
    m << q(0), q(3) / 2, q(4) / 2, q(6) / 2,  //
        q(3) / 2, q(1), q(5) / 2, q(7) / 2,   //
        q(4) / 2, q(5) / 2, q(2), q(8) / 2,   //
        q(6) / 2, q(7) / 2, q(8) / 2, q(9);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(m, Eigen::EigenvaluesOnly);
    Eigen::Vector4d a = eig.eigenvalues().cwiseAbs();
    std::sort(a.data(), a.data() + 4);
    return a(1) < 1e-3 * a(3);
  }
  // First-order signed distance of p to the quadric [m].
  double Distance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d y = (p - mean) / scale;
    const double g = (J(y) * q).norm();
    return g > 0.0 ? scale * V(y).dot(q) / g : std::numeric_limits<double>::infinity();
  }
  // Newton steps along the gradient onto the quadric; false when they do
  // not settle within `max_move_m` of the start.
  bool Project(Eigen::Vector3d* p, double max_move_m) const {
    const Eigen::Vector3d start = *p;
    Eigen::Vector3d y = (*p - mean) / scale;
    // The sheet puts p within ~1 mm: Newton converges in a few steps.
    for (int it = 0; it < 3; ++it) {
      const Eigen::Vector3d g = J(y) * q;
      const double g2 = g.squaredNorm();
      if (!(g2 > 0.0)) return false;
      y -= (V(y).dot(q) / g2) * g;
    }
    *p = mean + scale * y;
    return std::abs(Distance(*p)) < 1e-6 && (*p - start).norm() <= max_move_m;
  }
};

// Taubin's fit (least algebraic error over gradient norm: a generalized
// eigenproblem, the constant term eliminated) with Tukey reweighting of the
// geometric residuals, starting from `weights`.
bool FitQuadric(const PointList& points, const std::vector<int>& support,
                std::vector<double> weights, int iterations, double sigma_floor_m, Quadric* out) {
  const size_t m = support.size();
  if (m < 30) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : support) mean += points[i].cast<double>();
  mean /= static_cast<double>(m);
  double rms = 0.0;
  for (int i : support) rms += (points[i].cast<double>() - mean).squaredNorm();
  out->mean = mean;
  out->scale = std::sqrt(rms / static_cast<double>(m));
  if (!(out->scale > 0.0)) return false;
  std::vector<Eigen::Vector3d> y(m);
  for (size_t k = 0; k < m; ++k) y[k] = (points[support[k]].cast<double>() - mean) / out->scale;
  std::vector<double> abs_residual(m);
  for (int it = 0; it < iterations; ++it) {
    double wsum = 0.0;
    Eigen::Matrix<double, 9, 1> vbar = Eigen::Matrix<double, 9, 1>::Zero();
    for (size_t k = 0; k < m; ++k) {
      wsum += weights[k];
      vbar += weights[k] * Quadric::V(y[k]).head<9>();
    }
    if (!(wsum > 0.0)) return false;
    vbar /= wsum;
    Eigen::Matrix<double, 9, 9> mm = Eigen::Matrix<double, 9, 9>::Zero();
    Eigen::Matrix<double, 9, 9> nn = Eigen::Matrix<double, 9, 9>::Zero();
    for (size_t k = 0; k < m; ++k) {
      if (weights[k] <= 0.0) continue;
      const Eigen::Matrix<double, 9, 1> v = Quadric::V(y[k]).head<9>() - vbar;
      const Eigen::Matrix<double, 3, 9> j = Quadric::J(y[k]).leftCols<9>();
      mm += weights[k] * v * v.transpose();
      nn += weights[k] * j.transpose() * j;
    }
    nn.diagonal().array() += 1e-12 * nn.trace();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> ges(mm, nn);
    if (ges.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 9, 1> q9 = ges.eigenvectors().col(0);
    out->q.head<9>() = q9;
    out->q(9) = -vbar.dot(q9);
    if (!out->q.allFinite()) return false;
    for (size_t k = 0; k < m; ++k) {
      abs_residual[k] = std::abs(out->Distance(points[support[k]].cast<double>()));
    }
    std::vector<double> sorted = abs_residual;
    out->sigma_m = 1.4826 * Median(sorted);
    const double c = 4.685 * std::max(out->sigma_m, sigma_floor_m);
    for (size_t k = 0; k < m; ++k) {
      const double r = abs_residual[k] / c;
      weights[k] = r < 1.0 ? (1.0 - r * r) * (1.0 - r * r) : 0.0;
    }
  }
  return true;
}

// Largest area element the sampler draws candidates for (a slope of ~76
// degrees); steeper parts are sampled at kMaxAreaElement / J of the density.
constexpr double kMaxAreaElement = 4.0;

// Samples the height field over the region's (u, v) rectangle at `density`
// per m^2 of surface: uniform in (u, v), thinned by the area element so
// that the density holds on the curved surface too. With `snap`, each
// sample is moved onto that quadric (and dropped if it would move more
// than `max_snap_m`). With `clip`, only the
// samples at most `clip_tol_m` above that other sheet are kept (the two
// faces of a convex edge: each is the surface where it lies inside the
// other).
template <typename Sheet>
void SampleHeightField(const Sheet& hf, const FillRegion& region, double density,
                       const HeightField* clip, double clip_tol_m, const Quadric* snap,
                       double max_snap_m, Uniform01* rng, GapTest* gap, PointList* out) {
  const double u0 = region.lo.x(), u1 = region.hi.x(), v0 = region.lo.y(), v1 = region.hi.y();
  double j_max = 1.0;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 8; ++j) {
      j_max = std::max(j_max, hf.AreaElement(u0 + (u1 - u0) * i / 8.0, v0 + (v1 - v0) * j / 8.0));
    }
  }
  j_max *= 1.05;  // the 9 x 9 grid may miss the true maximum a little
  // Where the sheet stands steeper than ~76 degrees to its plane (a
  // polynomial running off past the rim, on a sphere's hole) it is sampled
  // a little thinner, instead of drawing millions of candidates to keep a
  // few (the ball's second hole: j_max 481, 3.9 M candidates, 0.4 s).
  j_max = std::min(j_max, kMaxAreaElement);
  const double expected = density * (u1 - u0) * (v1 - v0) * j_max;
  const auto count = static_cast<long>(std::min(expected, 5e6));
  for (long i = 0; i < count; ++i) {
    const double u = u0 + (u1 - u0) * (*rng)();
    const double v = v0 + (v1 - v0) * (*rng)();
    if ((*rng)() * j_max > hf.AreaElement(u, v)) continue;
    Eigen::Vector3d q = hf.Point(u, v);
    if (!hf.Holds(q)) continue;
    if (snap != nullptr && !snap->Project(&q, max_snap_m)) continue;
    if (!region.InZ(q.z())) continue;
    if (clip != nullptr && clip->Above(q) > clip_tol_m) continue;
    const Eigen::Vector3f p = q.cast<float>();
    if (gap->IsNew(p)) out->push_back(p);
  }
}

// The smoothest height field over the rim's plane through the points
// around the hole: a thin-plate spline w(u, v) = a0 + a1 u + a2 v +
// sum_i c_i phi(|(u, v) - x_i|), phi(r) = r^2 log r (Duchon 1977), fitted
// with a little smoothing to the mean of the support in each cell of a
// (u, v) grid (at most `max_centres` cells: the solve is dense). It is the
// fallback when no polynomial sheet, quadric or pair of faces explains the
// hole: a rounded edge, a rim that a fused cloud leaves ragged. Unlike those
// it assumes no shape, only that the surface is a graph over the rim's
// plane; the samples are kept within the support's range of heights.
struct ThinPlateSheet {
  HoleFrame frame;
  double scale{1.0};  // (u, v, w) divided by it in the solve
  std::vector<Eigen::Vector2d> centres;  // scaled
  Eigen::VectorXd c;                     // per centre
  Eigen::Vector3d affine{Eigen::Vector3d::Zero()};
  double w_lo{0.0}, w_hi{0.0};  // the support's heights [m]
  double w_pad{0.0};

  static double Phi(double r2) { return r2 > 0.0 ? 0.5 * r2 * std::log(r2) : 0.0; }
  // Height [m] at (u, v) [m], and its gradient when asked.
  double Height(double u, double v, Eigen::Vector2d* gradient = nullptr) const {
    const Eigen::Vector2d x(u / scale, v / scale);
    double w = affine(0) + affine(1) * x.x() + affine(2) * x.y();
    Eigen::Vector2d g(affine(1), affine(2));
    for (size_t i = 0; i < centres.size(); ++i) {
      const Eigen::Vector2d d = x - centres[i];
      const double r2 = d.squaredNorm();
      if (r2 <= 0.0) continue;
      const double l = std::log(r2);
      w += c(static_cast<long>(i)) * 0.5 * r2 * l;
      if (gradient) g += c(static_cast<long>(i)) * (l + 1.0) * d;
    }
    if (gradient) *gradient = g;  // dw/du in m/m: the scale cancels
    return w * scale;
  }
  Eigen::Vector3d Point(double u, double v) const { return frame.World(u, v, Height(u, v)); }
  double Above(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d l = frame.Local(p);
    return l.z() - Height(l.x(), l.y());
  }
  // Only within the support's heights (padded by `w_pad`): past them the
  // spline extrapolates.
  bool Holds(const Eigen::Vector3d& p) const {
    const double w = frame.Local(p).z();
    return w >= w_lo - w_pad && w <= w_hi + w_pad;
  }
  double AreaElement(double u, double v) const {
    Eigen::Vector2d g;
    Height(u, v, &g);
    return std::sqrt(1.0 + g.squaredNorm());
  }
};

// Centres of the thin-plate fallback: a dense (n + 3)^2 solve, ~5 ms at 256.
constexpr int kThinPlateCentres = 256;

bool FitThinPlate(const NeighborIndex& index, const std::vector<int>& support,
                  const HoleFrame& frame, const Eigen::Vector3f& centroid, double d,
                  int max_centres, ThinPlateSheet* out) {
  // Only the points that face the way the hole does (their normals within
  // 60 degrees of n): the support box also catches the faces beside the
  // hole's, which are no graph over its plane.
  const PointList& points = index.points();
  const std::vector<int> sample = Thin(support, 1500);
  const std::vector<Eigen::Vector3f> normals = EstimateNormals(index, sample, 10, centroid);
  const Eigen::Vector3f n = frame.n.cast<float>();
  std::vector<Eigen::Vector3d> local;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()),
                  hi = -lo;
  for (size_t k = 0; k < sample.size(); ++k) {
    if (normals[k].dot(n) < 0.5f) continue;
    local.push_back(frame.Local(points[sample[k]].cast<double>()));
    lo = lo.cwiseMin(local.back().head<2>());
    hi = hi.cwiseMax(local.back().head<2>());
  }
  if (local.size() < 30) return false;
  out->frame = frame;
  const Eigen::Vector2d size = (hi - lo).cwiseMax(d);
  // Cells of ~1/max_centres of the box's area (the hole leaves some
  // empty), never finer than 2 D.
  const double cell = std::max(2.0 * d, std::sqrt(size.x() * size.y() / max_centres));
  const int nu = static_cast<int>(size.x() / cell) + 1, nv = static_cast<int>(size.y() / cell) + 1;
  std::vector<Eigen::Vector4d> sums(static_cast<size_t>(nu) * nv, Eigen::Vector4d::Zero());
  for (const Eigen::Vector3d& l : local) {
    const int iu = std::min(nu - 1, static_cast<int>((l.x() - lo.x()) / cell));
    const int iv = std::min(nv - 1, static_cast<int>((l.y() - lo.y()) / cell));
    sums[static_cast<size_t>(iv) * nu + iu] += Eigen::Vector4d(l.x(), l.y(), l.z(), 1.0);
  }
  out->scale = std::max(size.maxCoeff(), 1e-6);
  std::vector<Eigen::Vector3d> data;  // cell means, scaled
  for (const Eigen::Vector4d& s : sums) {
    if (s(3) >= 1.0) data.push_back(s.head<3>() / (s(3) * out->scale));
  }
  // Twice: a fit, then again without the cells it leaves far off (a curl
  // of the TSDF at the rim, a stray patch of the finger).
  std::vector<char> use(data.size(), 1);
  for (int pass = 0; pass < 2; ++pass) {
    out->centres.clear();
    std::vector<double> w;
    for (size_t i = 0; i < data.size(); ++i) {
      if (!use[i]) continue;
      out->centres.push_back(data[i].head<2>());
      w.push_back(data[i].z());
    }
    const long n = static_cast<long>(out->centres.size());
    if (n < 10) return false;
    // Smoothing: the cells' mean heights carry noise of a fraction of D.
    const double lambda = 1e-6;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n + 3, n + 3);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 3);
    for (long i = 0; i < n; ++i) {
      for (long j = 0; j < i; ++j) {
        a(i, j) = a(j, i) = ThinPlateSheet::Phi((out->centres[i] - out->centres[j]).squaredNorm());
      }
      a(i, i) = lambda * static_cast<double>(n);
      a(i, n) = a(n, i) = 1.0;
      a(i, n + 1) = a(n + 1, i) = out->centres[i].x();
      a(i, n + 2) = a(n + 2, i) = out->centres[i].y();
      b(i) = w[i];
    }
    const Eigen::VectorXd x = a.partialPivLu().solve(b);
    if (!x.allFinite()) return false;
    out->c = x.head(n);
    out->affine = x.tail<3>();
    if (pass == 1) break;
    std::vector<double> r(data.size());
    for (size_t i = 0; i < data.size(); ++i) {
      r[i] = std::abs(data[i].z() * out->scale -
                      out->Height(data[i].x() * out->scale, data[i].y() * out->scale));
    }
    std::vector<double> sorted = r;
    const double cut = std::max(3.0 * 1.4826 * Median(sorted), d);
    bool dropped = false;
    for (size_t i = 0; i < data.size(); ++i) {
      if (r[i] > cut) use[i] = 0, dropped = true;
    }
    if (!dropped) break;
  }
  out->w_lo = std::numeric_limits<double>::infinity();
  out->w_hi = -out->w_lo;
  for (const Eigen::Vector3d& l : local) {
    out->w_lo = std::min(out->w_lo, l.z());
    out->w_hi = std::max(out->w_hi, l.z());
  }
  out->w_pad = 2.0 * d;  // the caller may widen it
  return true;
}

// The support points in front of the cloud's centroid along n: on a convex
// object they form one sheet over the plane (the far side of a narrow top,
// or of a small object, would fold the height field).
std::vector<int> FrontOf(const PointList& points, const std::vector<int>& support,
                         const Eigen::Vector3d& n, const Eigen::Vector3f& centroid) {
  std::vector<int> front;
  for (int i : support) {
    if ((points[i] - centroid).cast<double>().dot(n) > 0.0) front.push_back(i);
  }
  return front;
}

// The surface of one claw hole, the candidate most consistent with the
// points around it and with its rim:
//  - one polynomial sheet over the rim's plane, or one quadric (chosen when
//    its residuals are less than half the sheet's: curved holes);
//  - else (a hole across a convex edge, e.g. at a cuboid's corner) two
//    sheets, one per face, the faces told apart by the points' normals,
//    each sheet used where it lies inside the other;
//  - else nothing (false): the caller falls back to Poisson.
struct Sheets {
  HeightField a, b;
  bool two{false};
  Quadric quadric;
  bool use_quadric{false};
};

HoleFrame FrameFromPlane(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3f& centroid) {
  HoleFrame f;
  Eigen::Vector3d eigenvalues;
  f.n = PlaneOf(pts, &f.origin, &eigenvalues);
  if ((f.origin - centroid.cast<double>()).dot(f.n) < 0.0) f.n = -f.n;
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitZ() - f.n.z() * f.n;
  if (e2.norm() < 0.1) e2 = Eigen::Vector3d::UnitX() - f.n.x() * f.n;
  f.e2 = e2.normalized();
  f.e1 = f.e2.cross(f.n);
  return f;
}

bool FitSheets(const NeighborIndex& index, const std::vector<int>& support, const PointList& rim,
               const HoleFrame& frame, const Eigen::Vector3f& centroid,
               const ClawRepairConfig& config, double d, Sheets* out) {
  const PointList& points = index.points();
  const double floor = 0.05 * d;
  const int max_outliers = static_cast<int>(0.1 * static_cast<double>(rim.size()));
  // A rim point lies on a surface when within its fit's Tukey cut-off, and
  // never closer than 2 D or 0.5 mm is asked for.
  const auto tol = [&](double sigma) { return std::max({4.685 * sigma, 2.0 * d, 0.0005}); };
  const auto rim_ok = [&](const auto& distance, double t) {
    int n = 0;
    for (const Eigen::Vector3f& p : rim) n += !(std::abs(distance(p.cast<double>())) <= t);
    return n <= max_outliers;
  };
  // Robust residual scale of a candidate over the same points for all.
  const std::vector<int> front = FrontOf(points, support, frame.n, centroid);
  const std::vector<int> probe = Thin(front, 1000);
  const auto sigma_of = [&](const auto& distance) {
    std::vector<double> r;
    for (int i : probe) r.push_back(std::abs(distance(points[i].cast<double>())));
    return 1.4826 * Median(r);
  };

  // 1. One sheet over the rim's plane: a tenth of the spacing off the
  // points is as good as the data (flat faces, cylinders): done.
  HeightField sheet;
  const bool sheet_fits = FitHeightField(points, front, frame, config.polynomial_degree,
                                         config.irls_iterations, floor, &sheet) &&
                          sheet.sigma_m <= config.max_fit_sigma_m;
  const auto sheet_distance = [&](const Eigen::Vector3d& p) { return sheet.Above(p); };
  const bool sheet_ok = sheet_fits && rim_ok(sheet_distance, tol(sheet.sigma_m));
  if (sheet_ok && sheet.sigma_m <= 0.1 * d) {
    out->a = sheet;
    return true;
  }
  double best = sheet_ok ? sigma_of(sheet_distance) : std::numeric_limits<double>::infinity();
  int choice = sheet_ok ? 0 : -1;

  // 2. A quadric (curved faces: spheres, ellipsoids), never a pair of
  // planes. It starts from the points the sheet kept, and its samples are
  // placed by the sheet then moved onto it.
  if (sheet_fits) {
    std::vector<double> w(probe.size());
    const double tol_sheet = tol(sheet.sigma_m);
    for (size_t k = 0; k < probe.size(); ++k) {
      w[k] = std::abs(sheet.Above(points[probe[k]].cast<double>())) <= tol_sheet ? 1.0 : 0.0;
    }
    Quadric quadric;
    if (FitQuadric(points, probe, w, config.irls_iterations, floor, &quadric) &&
        !quadric.IsPlanePair()) {
      const auto distance = [&](const Eigen::Vector3d& p) { return quadric.Distance(p); };
      const double sigma = sigma_of(distance);
      if (sigma < 0.5 * best && rim_ok(distance, tol(quadric.sigma_m))) {
        best = sigma;
        choice = 1;
        out->quadric = quadric;
      }
    }
  }
  if (choice == 1 && best <= 0.1 * d) {  // as good as the data
    out->a = sheet;
    out->use_quadric = true;
    return true;
  }

  // 3. Two faces of a convex edge (a hole at a cuboid's corner): the
  // support's normals split around the two most common directions (30
  // degree cones), one sheet per face, each used where it lies inside the
  // other.
  // 500 points, a few hundred per face, plenty for the sheets' fits; 10
  // neighbours tell the faces apart (KD queries are most of this step).
  const std::vector<int> sample = Thin(support, 500);
  const std::vector<Eigen::Vector3f> normals =
      EstimateNormals(index, sample, std::min(config.normal_knn, 10), centroid);
  const float cos_cone = std::cos(30.0f * static_cast<float>(M_PI) / 180.0f);
  const auto count_near = [&](const Eigen::Vector3f& n, const Eigen::Vector3f* exclude) {
    int c = 0;
    for (const Eigen::Vector3f& m : normals) {
      if (exclude != nullptr && m.dot(*exclude) >= cos_cone) continue;
      c += m.dot(n) >= cos_cone;
    }
    return c;
  };
  const size_t stride = std::max<size_t>(1, normals.size() / 64);
  Eigen::Vector3f na = normals[0], nb = Eigen::Vector3f::Zero();
  int most = -1;
  for (size_t i = 0; i < normals.size(); i += stride) {
    const int c = count_near(normals[i], nullptr);
    if (c > most) most = c, na = normals[i];
  }
  most = -1;
  for (size_t i = 0; i < normals.size(); i += stride) {
    if (normals[i].dot(na) >= cos_cone) continue;
    const int c = count_near(normals[i], &na);
    if (c > most) most = c, nb = normals[i];
  }
  std::vector<int> group_a, group_b;
  std::vector<Eigen::Vector3d> pts_a, pts_b;
  for (size_t k = 0; k < sample.size(); ++k) {
    if (normals[k].dot(na) >= cos_cone) {
      group_a.push_back(sample[k]);
      pts_a.push_back(points[sample[k]].cast<double>());
    } else if (nb.squaredNorm() > 0.0f && normals[k].dot(nb) >= cos_cone) {
      group_b.push_back(sample[k]);
      pts_b.push_back(points[sample[k]].cast<double>());
    }
  }
  HeightField a, b;
  const int min_points = 3 * HeightField::NumTerms(config.polynomial_degree);
  const Eigen::Vector3d c = centroid.cast<double>();
  if (static_cast<int>(group_a.size()) >= min_points &&
      static_cast<int>(group_b.size()) >= min_points &&
      FitHeightField(points, group_a, FrameFromPlane(pts_a, centroid), config.polynomial_degree,
                     config.irls_iterations, floor, &a) &&
      FitHeightField(points, group_b, FrameFromPlane(pts_b, centroid), config.polynomial_degree,
                     config.irls_iterations, floor, &b) &&
      a.sigma_m <= config.max_fit_sigma_m && b.sigma_m <= config.max_fit_sigma_m &&
      a.Above(c) < 0.0 && b.Above(c) < 0.0) {  // convex edge only
    const double ta = tol(a.sigma_m), tb = tol(b.sigma_m);
    const auto distance = [&](const Eigen::Vector3d& p) {
      return std::min(std::abs(a.Above(p)), std::abs(b.Above(p)));
    };
    const auto explained = [&](const Eigen::Vector3d& p) {
      return std::abs(a.Above(p)) <= ta || std::abs(b.Above(p)) <= tb ? 0.0 : 1.0;
    };
    const double sigma = sigma_of(distance);
    if (sigma < 0.5 * best && rim_ok(explained, 0.5)) {
      best = sigma;
      choice = 2;
      out->a = a;
      out->b = b;
    }
  }
  if (choice < 0) return false;
  out->use_quadric = choice == 1;
  out->two = choice == 2;
  if (choice != 2) out->a = sheet;
  return true;
}

// ---------------------------------------------------------------------------
// Poisson.

struct PoissonSurface {
  std::shared_ptr<open3d::geometry::TriangleMesh> mesh;
  std::vector<double> densities;
  double cell_m{0.0};  ///< edge of the finest octree cell
};

PoissonSurface ReconstructPoisson(const PointList& points, const std::vector<int>& subset,
                                  const std::vector<Eigen::Vector3f>& normals, int depth,
                                  double scale) {
  open3d::geometry::PointCloud pcd;
  pcd.points_.reserve(subset.size());
  pcd.normals_.reserve(subset.size());
  Box extent;
  extent.setEmpty();
  for (size_t i = 0; i < subset.size(); ++i) {
    pcd.points_.push_back(points[subset[i]].cast<double>());
    pcd.normals_.push_back(normals[i].cast<double>());
    extent.extend(points[subset[i]]);
  }
  PoissonSurface out;
  out.cell_m = subset.empty() ? 0.0 : scale * extent.sizes().maxCoeff() / std::ldexp(1.0, depth);
  // One thread: the repair runs single-threaded and stays deterministic.
  std::tie(out.mesh, out.densities) = open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(
      pcd, static_cast<size_t>(depth), 0.0f, static_cast<float>(scale), false, 1);
  return out;
}

// Samples, at `density` per m^2, the triangles that reach into `region`
// (in `frame`), whose vertices are all kept (`keep_vertex`, may be null),
// and that face within acos(cos_max_angle) of frame.n when `check_facing`
// (the mesh winds outwards, as its input normals point; this drops the far
// side of a closed Poisson surface); keeps the samples inside the region
// that pass the gap test.
void SampleMesh(const open3d::geometry::TriangleMesh& mesh, const HoleFrame& frame,
                const FillRegion& region, bool check_facing, double cos_max_angle,
                const std::vector<bool>* keep_vertex, double density, Uniform01* rng,
                GapTest* gap, PointList* out) {
  std::vector<int> tris;
  std::vector<double> cumulative;
  double total = 0.0;
  const Eigen::AlignedBox3d region_box(region.lo, region.hi);
  for (size_t t = 0; t < mesh.triangles_.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles_[t];
    if (keep_vertex != nullptr &&
        !((*keep_vertex)[tri(0)] && (*keep_vertex)[tri(1)] && (*keep_vertex)[tri(2)])) {
      continue;
    }
    const Eigen::Vector3d& a = mesh.vertices_[tri(0)];
    const Eigen::Vector3d& b = mesh.vertices_[tri(1)];
    const Eigen::Vector3d& c = mesh.vertices_[tri(2)];
    Eigen::AlignedBox3d local(frame.Local(a));
    local.extend(frame.Local(b));
    local.extend(frame.Local(c));
    if (!local.intersects(region_box)) continue;
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area2 = cross.norm();
    if (area2 <= 0.0) continue;
    if (check_facing && cross.dot(frame.n) < cos_max_angle * area2) continue;
    total += 0.5 * area2;
    tris.push_back(static_cast<int>(t));
    cumulative.push_back(total);
  }
  if (tris.empty()) return;
  const double expected = std::min(total * density, 5e6);
  // Stochastic rounding keeps the expected count exact for small patches.
  auto count = static_cast<long>(expected);
  if ((*rng)() < expected - static_cast<double>(count)) ++count;
  for (long i = 0; i < count; ++i) {
    const double pick = (*rng)() * total;
    const size_t k = std::min<size_t>(
        tris.size() - 1,
        static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                            cumulative.begin()));
    const Eigen::Vector3i& tri = mesh.triangles_[tris[k]];
    const double r1 = std::sqrt((*rng)()), r2 = (*rng)();
    const Eigen::Vector3d p = (1.0 - r1) * mesh.vertices_[tri(0)] +
                              r1 * (1.0 - r2) * mesh.vertices_[tri(1)] +
                              r1 * r2 * mesh.vertices_[tri(2)];
    if (!region.Contains(frame.Local(p)) || !region.InZ(p.z())) continue;
    const Eigen::Vector3f pf = p.cast<float>();
    if (gap->IsNew(pf)) out->push_back(pf);
  }
}

Eigen::Vector3f Centroid(const PointList& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) sum += p.cast<double>();
  return (sum / static_cast<double>(std::max<size_t>(1, points.size()))).cast<float>();
}

}  // namespace

ClawRepairConfig ClawRepairConfig::Paper() {
  ClawRepairConfig config;
  config.surface = ClawSurface::kPoisson;
  config.local_reconstruction = false;
  config.poisson_depth = 6;
  config.poisson_scale = 4.0;
  return config;
}

void ClawRepairConfig::Validate() const {
  const std::string p = "ClawRepairConfig.";
  Require(local_margin_m > 0.0 && std::isfinite(local_margin_m), p + "local_margin_m must be > 0");
  Require(exclude_top_band_m >= 0.0 && std::isfinite(exclude_top_band_m),
          p + "exclude_top_band_m must be >= 0");
  Require(min_support_points >= 3, p + "min_support_points must be >= 3");
  Require(polynomial_degree >= 1 && polynomial_degree <= 5,
          p + "polynomial_degree must be in [1, 5]");
  Require(max_fit_sigma_m > 0.0, p + "max_fit_sigma_m must be > 0");
  Require(irls_iterations >= 3 && irls_iterations <= 100, p + "irls_iterations must be in [3, 100]");
  Require(poisson_depth >= 2 && poisson_depth <= 12, p + "poisson_depth must be in [2, 12]");
  Require(poisson_scale >= 1.0 && poisson_scale <= 16.0, p + "poisson_scale must be in [1, 16]");
  Require(normal_knn >= 3 && normal_knn <= 200, p + "normal_knn must be in [3, 200]");
  Require(max_normal_deviation_deg > 0.0 && max_normal_deviation_deg <= 180.0,
          p + "max_normal_deviation_deg must be in (0, 180]");
  Require(poisson_box_pad_cells >= 0.0 && poisson_box_pad_cells <= 100.0,
          p + "poisson_box_pad_cells must be in [0, 100]");
  Require(fill_density_factor > 0.0 && fill_density_factor <= 100.0,
          p + "fill_density_factor must be in (0, 100]");
  Require(min_gap_d >= 0.0 && min_gap_d <= 100.0, p + "min_gap_d must be in [0, 100]");
  Require(box_pad_d >= 0.0 && box_pad_d <= 100.0, p + "box_pad_d must be in [0, 100]");
}

void PoissonFillConfig::Validate() const {
  const std::string p = "PoissonFillConfig.";
  Require(poisson_depth >= 2 && poisson_depth <= 12, p + "poisson_depth must be in [2, 12]");
  Require(poisson_scale >= 1.0 && poisson_scale <= 16.0, p + "poisson_scale must be in [1, 16]");
  Require(normal_knn >= 3 && normal_knn <= 200, p + "normal_knn must be in [3, 200]");
  Require(density_trim_quantile >= 0.0 && density_trim_quantile < 1.0,
          p + "density_trim_quantile must be in [0, 1)");
  Require(crop_pad_fraction >= 0.0 && crop_pad_fraction <= 10.0,
          p + "crop_pad_fraction must be in [0, 10]");
  Require(min_gap_d >= 0.0 && min_gap_d <= 100.0, p + "min_gap_d must be in [0, 100]");
  Require(fill_density_factor > 0.0 && fill_density_factor <= 100.0,
          p + "fill_density_factor must be in (0, 100]");
}

PointList RepairClawHoles(const PointList& points_V, const std::vector<HoleBoundary>& claw_holes,
                          const ClawRepairConfig& config,
                          const std::vector<Eigen::Vector3f>* normals_V,
                          const NeighborIndex* index_V) {
  config.Validate();
  CheckInputs(points_V, normals_V, index_V, "RepairClawHoles");
  PointList out;
  if (points_V.empty()) return out;
  std::vector<const HoleBoundary*> holes;
  for (const HoleBoundary& hole : claw_holes) {
    if (hole.kind == HoleKind::kClaw && hole.points_V.size() >= 3) {
      CheckFinite(hole.points_V, "RepairClawHoles: claw-hole boundary");
      holes.push_back(&hole);
    }
  }
  if (holes.empty()) return out;

  std::unique_ptr<NeighborIndex> own_index;
  if (index_V == nullptr) {
    own_index = std::make_unique<NeighborIndex>(points_V);
    index_V = own_index.get();
  }
  const NeighborIndex& index = *index_V;
  const Eigen::Vector3f centroid = Centroid(points_V);
  float max_z = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : points_V) max_z = std::max(max_z, p.z());
  const float z_cut = config.exclude_top_band_m > 0.0
                          ? max_z - static_cast<float>(config.exclude_top_band_m)
                          : std::numeric_limits<float>::infinity();
  const double cos_max = std::cos(config.max_normal_deviation_deg * M_PI / 180.0);

  // Normals of a subset: the caller's, else estimated on demand.
  const auto normals_of = [&](const std::vector<int>& subset) {
    if (normals_V == nullptr) return EstimateNormals(index, subset, config.normal_knn, centroid);
    std::vector<Eigen::Vector3f> n(subset.size());
    for (size_t i = 0; i < subset.size(); ++i) n[i] = (*normals_V)[subset[i]];
    return n;
  };
  // The paper's single surface of all the side points, built on first use.
  std::unique_ptr<PoissonSurface> global_surface;

  std::unique_ptr<AddedPoints> earlier;  // the fills of the holes before
  for (size_t h = 0; h < holes.size(); ++h) {
    const PointList& rim = holes[h]->points_V;
    Box box;
    box.setEmpty();
    for (const Eigen::Vector3f& p : rim) box.extend(p);
    const float margin = static_cast<float>(config.local_margin_m);
    const Box support_box(box.min() - Eigen::Vector3f::Constant(margin),
                          box.max() + Eigen::Vector3f::Constant(margin));
    std::vector<int> near, support;  // in the box; and below the top band
    for (size_t i = 0; i < points_V.size(); ++i) {
      if (support_box.contains(points_V[i])) {
        near.push_back(static_cast<int>(i));
        if (points_V[i].z() <= z_cut) support.push_back(static_cast<int>(i));
      }
    }
    if (static_cast<int>(support.size()) < config.min_support_points) continue;
    const Spacing spacing = EstimateSpacing(index, support, 200);
    if (spacing.mean_nn_m <= 0.0 || spacing.density_per_m2 <= 0.0) continue;
    const double d = spacing.mean_nn_m;
    const double density = spacing.density_per_m2 * config.fill_density_factor;
    const double gap_m = config.min_gap_d * d;
    if (!earlier) earlier = std::make_unique<AddedPoints>(std::max(gap_m, 1e-4));
    Uniform01 rng(MixSeed(config.seed, h));

    // Outward: the caller's normals when given, else away from the centroid.
    Eigen::Vector3d outward = Eigen::Vector3d::Zero();
    if (normals_V != nullptr) {
      for (int i : support) outward += (*normals_V)[i].cast<double>();
    }
    if (outward.norm() < 1e-9) outward = (box.center() - centroid).cast<double>();
    const HoleFrame frame = MakeHoleFrame(rim, points_V, support, outward);
    const double pad = config.box_pad_d * d;
    FillRegion region = RimRegion(rim, frame, pad, box.min().z() - pad, box.max().z() + pad);
    // The grid spans the support box's shadow, so that the samples of a
    // second sheet (an edge hole), too, are tested on it.
    Eigen::Vector2d grid_lo = region.lo.head<2>(), grid_hi = region.hi.head<2>();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d l =
          frame.Local(support_box.corner(static_cast<Box::CornerType>(c)).cast<double>());
      grid_lo = grid_lo.cwiseMin(l.head<2>());
      grid_hi = grid_hi.cwiseMax(l.head<2>());
    }
    GapTest gap(index, earlier.get(), gap_m);
    gap.BuildGrid(frame, grid_lo, grid_hi, near, support_box, out);

    PointList fill;
    bool filled = false;
    Sheets sheets;
    // Otherwise the points around the hole are not one or two smooth
    // sheets: the hole falls back to a local Poisson surface below.
    if (config.surface == ClawSurface::kLocalFit &&
        FitSheets(index, support, rim, frame, centroid, config, d, &sheets)) {
      const double clip_tol = 0.5 * d;
      // The sheet parametrizes the quadric's samples: it is within ~1 mm.
      const double max_snap = std::max(0.003, 10.0 * d);
      // Each sheet over the rim's shadow in its own frame.
      const auto region_of = [&](const HoleFrame& f) {
        return RimRegion(rim, f, pad, region.z_lo, region.z_hi);
      };
      SampleHeightField(sheets.a, region_of(sheets.a.frame), density,
                        sheets.two ? &sheets.b : nullptr, clip_tol,
                        sheets.use_quadric ? &sheets.quadric : nullptr, max_snap, &rng, &gap,
                        &fill);
      if (sheets.two) {
        SampleHeightField(sheets.b, region_of(sheets.b.frame), density, &sheets.a, clip_tol,
                          nullptr, 0.0, &rng, &gap, &fill);
      }
      filled = true;
    }
    ThinPlateSheet smooth;
    if (!filled && config.surface == ClawSurface::kLocalFit &&
        FitThinPlate(index, support, frame, centroid, d, kThinPlateCentres, &smooth)) {
      // Its heights may pass the support's by the bulge of a convex face
      // over the hole (a^2 / 2r, bounded by a quarter of the hole's width).
      smooth.w_pad = 2.0 * d + 0.25 * (region.hi.head<2>() - region.lo.head<2>()).minCoeff();
      SampleHeightField(smooth, region, density, nullptr, 0.0, nullptr, 0.0, &rng, &gap, &fill);
      filled = true;
    }
    if (!filled && config.surface == ClawSurface::kPoisson) {
      PoissonSurface local;
      const PoissonSurface* surface = &local;
      if (config.surface == ClawSurface::kPoisson && !config.local_reconstruction) {
        if (!global_surface) {
          std::vector<int> side;
          for (size_t i = 0; i < points_V.size(); ++i) {
            if (points_V[i].z() <= z_cut) side.push_back(static_cast<int>(i));
          }
          global_surface = std::make_unique<PoissonSurface>(ReconstructPoisson(
              points_V, side, normals_of(side), config.poisson_depth, config.poisson_scale));
        }
        surface = global_surface.get();
      } else {
        local = ReconstructPoisson(points_V, support, normals_of(support), config.poisson_depth,
                                   config.poisson_scale);
      }
      // Along n: the rim's spread, the surface's sag or bulge over the hole
      // (up to about a cell, and the curvature's a^2 / 2r, bounded by a
      // quarter of the hole's width), and the pad.
      const double n_pad = pad + config.poisson_box_pad_cells * surface->cell_m +
                           0.25 * (region.hi.head<2>() - region.lo.head<2>()).minCoeff();
      region.lo.z() -= n_pad;
      region.hi.z() += n_pad;
      SampleMesh(*surface->mesh, frame, region, true, cos_max, nullptr, density, &rng, &gap, &fill);
    }
    for (const Eigen::Vector3f& p : fill) {
      earlier->Add(p);
      out.push_back(p);
    }
  }
  return out;
}

PointList PoissonFillAll(const PointList& points, const PoissonFillConfig& config,
                         const std::vector<Eigen::Vector3f>* normals,
                         const NeighborIndex* index) {
  config.Validate();
  CheckInputs(points, normals, index, "PoissonFillAll");
  PointList out;
  // Too few points for normals and a meaningful surface: nothing to fill.
  if (points.size() < static_cast<size_t>(2 * config.normal_knn)) return out;
  std::unique_ptr<NeighborIndex> own_index;
  if (index == nullptr) {
    own_index = std::make_unique<NeighborIndex>(points);
    index = own_index.get();
  }
  std::vector<int> all(points.size());
  for (size_t i = 0; i < points.size(); ++i) all[i] = static_cast<int>(i);
  const Spacing spacing = EstimateSpacing(*index, all, 2000);
  if (spacing.mean_nn_m <= 0.0 || spacing.density_per_m2 <= 0.0) return out;
  const double d = spacing.mean_nn_m;

  const std::vector<Eigen::Vector3f> n =
      normals != nullptr ? *normals
                         : EstimateNormals(*index, all, config.normal_knn, Centroid(points));
  const PoissonSurface surface =
      ReconstructPoisson(points, all, n, config.poisson_depth, config.poisson_scale);
  const open3d::geometry::TriangleMesh& mesh = *surface.mesh;
  if (mesh.triangles_.empty()) return out;

  double threshold = -std::numeric_limits<double>::infinity();
  if (config.density_trim_quantile > 0.0 && !surface.densities.empty()) {
    std::vector<double> sorted = surface.densities;
    const auto k = static_cast<size_t>(config.density_trim_quantile *
                                       static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(k), sorted.end());
    threshold = sorted[k];
  }
  Box bounds;
  bounds.setEmpty();
  for (const Eigen::Vector3f& p : points) bounds.extend(p);
  const double pad = config.crop_pad_fraction * bounds.sizes().maxCoeff();
  FillRegion crop;  // in the identity frame
  crop.lo = bounds.min().cast<double>() - Eigen::Vector3d::Constant(pad);
  crop.hi = bounds.max().cast<double>() + Eigen::Vector3d::Constant(pad);
  std::vector<bool> keep(mesh.vertices_.size());
  for (size_t v = 0; v < keep.size(); ++v) {
    const bool dense = v >= surface.densities.size() || surface.densities[v] >= threshold;
    keep[v] = dense && crop.Contains(mesh.vertices_[v]);
  }
  GapTest gap(*index, nullptr, config.min_gap_d * d);
  Uniform01 rng(MixSeed(config.seed, 0));
  SampleMesh(mesh, HoleFrame{}, crop, false, -1.0, &keep,
             spacing.density_per_m2 * config.fill_density_factor, &rng, &gap, &out);
  return out;
}

}  // namespace graspfill::repair
