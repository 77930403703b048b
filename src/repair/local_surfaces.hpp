// SPDX-License-Identifier: BSD-3-Clause
// The explicit surfaces a claw hole is filled from, in the hole's frame:
// polynomial height fields, implicit quadrics and the thin-plate spline
// fallback, and the sampler that draws a fill from any of them. Internal to
// the repair library.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "gap_test.hpp"
#include "hole_fill.hpp"

namespace graspfill::repair::fill {

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
  // The unit normal at (u, v), on n's side.
  Eigen::Vector3d Normal(double u, double v) const {
    BasisVec f, fu, fv;
    Basis(u, v, &f, &fu, &fv);
    return (frame.n - fu.dot(coeffs) * frame.e1 - fv.dot(coeffs) * frame.e2).normalized();
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
  // Area element sqrt(1 + h_u^2 + h_v^2) of the height field at (u, v),
  // and the height there (Point's) when asked.
  double AreaElement(double u, double v, double* height = nullptr) const {
    BasisVec f, fu, fv;
    Basis(u, v, &f, &fu, &fv);
    const double hu = fu.dot(coeffs), hv = fv.dot(coeffs);
    if (height) *height = f.dot(coeffs);
    return std::sqrt(1.0 + hu * hu + hv * hv);
  }
};

// Fits the height field to `support` by iteratively reweighted least
// squares with Tukey's biweight (c = 4.685 sigma, sigma = 1.4826 MAD):
// points of another face past a sharp edge, or across a fold, get weight 0
// instead of bending the surface. The first weights come from the
// residuals to the rim's plane (the frame's), not from a plain least-
// squares fit, which at a corner would split the difference between the
// two faces; the first two iterations fit a plane, the others the full
// degree. Returns false when there are too few points for the degree.
bool FitHeightField(const PointList& points, const std::vector<int>& support, const HoleFrame& frame,
                    int degree, int iterations, double sigma_floor_m, HeightField* hf);

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
    v << y.x() * y.x(), y.y() * y.y(), y.z() * y.z(), y.x() * y.y(), y.x() * y.z(), y.y() * y.z(), y.x(),
        y.y(), y.z(), 1.0;
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
  bool IsPlanePair() const;  // out of line: Eigen's 4x4 solver is slow to compile
  // The gradient's direction at p (either sign: the quadric has no outside).
  Eigen::Vector3d Gradient(const Eigen::Vector3d& p) const { return J((p - mean) / scale) * q; }
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
bool FitQuadric(const PointList& points, const std::vector<int>& support, std::vector<double> weights,
                int iterations, double sigma_floor_m, Quadric* out);

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
  double scale{1.0};                     // (u, v, w) divided by it in the solve
  std::vector<Eigen::Vector2d> centres;  // scaled
  Eigen::VectorXd c;                     // per centre
  Eigen::Vector3d affine{Eigen::Vector3d::Zero()};
  double w_lo{0.0}, w_hi{0.0};  // the support's heights [m]
  double w_pad{0.0};
  // A quadric through the same points, when it explains them to the noise
  // (a fruit, a small ball): over a wide hole the spline, which bends as
  // little as it can, sags below a curved face; its samples are then moved
  // onto the quadric.
  bool use_quadric{false};
  Quadric quadric;
  // The cloud's own surface where it has points: per cell of a (u, v) grid
  // the highest w of the support's points (NaN where none: the hole). A
  // sample more than `column_tol_m` off it floats over (or sinks under) a
  // surface the cloud shows, e.g. past a sharp edge whose other face the
  // fit left out.
  Eigen::Vector2d grid_lo{0.0, 0.0};
  double grid_cell{1.0};
  int nu{0}, nv{0};
  std::vector<double> column_top;
  double column_tol_m{0.0};

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
    const Eigen::Vector3d l = frame.Local(p);
    if (!(l.z() >= w_lo - w_pad && l.z() <= w_hi + w_pad)) return false;
    const double fu = std::floor((l.x() - grid_lo.x()) / grid_cell);
    const double fv = std::floor((l.y() - grid_lo.y()) / grid_cell);
    if (!(fu >= 0.0 && fu < nu && fv >= 0.0 && fv < nv)) return true;
    const double top = column_top[static_cast<size_t>(fv) * nu + static_cast<size_t>(fu)];
    return std::isnan(top) || std::abs(l.z() - top) <= column_tol_m;
  }
  // The area element at (u, v), and the height there when asked (one pass
  // over the centres for both).
  double AreaElement(double u, double v, double* height = nullptr) const {
    Eigen::Vector2d g;
    const double w = Height(u, v, &g);
    if (height) *height = w;
    return std::sqrt(1.0 + g.squaredNorm());
  }
};

// Centres of the thin-plate fallback: a dense (n + 3)^2 solve, ~5 ms at 256.
constexpr int kThinPlateCentres = 256;

bool FitThinPlate(const NeighborIndex& index, const std::vector<int>& support, const HoleFrame& frame,
                  const Eigen::Vector3f& centroid, double d, int max_centres, ThinPlateSheet* out);

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
void SampleHeightField(const Sheet& hf, const FillRegion& region, double density, const HeightField* clip,
                       double clip_tol_m, const Quadric* snap, double max_snap_m, Rng* rng, GapTest* gap,
                       PointList* out) {
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
    const double u = u0 + (u1 - u0) * rng->Uniform();
    const double v = v0 + (v1 - v0) * rng->Uniform();
    double w = 0.0;
    if (rng->Uniform() * j_max > hf.AreaElement(u, v, &w)) continue;
    Eigen::Vector3d q = hf.frame.World(u, v, w);  // hf.Point(u, v)
    if (!hf.Holds(q)) continue;
    if (snap != nullptr && !snap->Project(&q, max_snap_m)) continue;
    if (!region.InZ(q.z())) continue;
    if (clip != nullptr && clip->Above(q) > clip_tol_m) continue;
    const Eigen::Vector3f p = q.cast<float>();
    if (gap->IsNew(p)) out->push_back(p);
  }
}

}  // namespace graspfill::repair::fill
