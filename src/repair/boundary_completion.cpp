// SPDX-License-Identifier: BSD-3-Clause
#include "boundary_completion.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "clamped_int.hpp"
#include "geometry/circle_fit.hpp"

namespace graspfill::repair {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// A radius-on-height slope of the rim's band below this is no flaring wall.
constexpr double kMinWallSlope = 0.1;
// Runs of fewer boundary points than this between two gaps are no rim.
constexpr size_t kMinRimRun = 5;
// The tangent at a gap's end is taken over this many spacings of points.
constexpr double kTangentWindowSpacings = 6.0;
// Dense samples per spacing when measuring arc length, and their bounds.
constexpr double kDensePerSpacing = 8.0;
constexpr int kMinDense = 512;
constexpr int kMaxDense = 1 << 16;

double WrapPositive(double a) {  // to [0, 2 pi)
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

// Uniform cubic B-spline basis on segment parameter t in [0, 1).
void Basis(double t, double w[4]) {
  const double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
  w[0] = s * s * s / 6.0;
  w[1] = (3 * t3 - 6 * t2 + 4) / 6.0;
  w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6.0;
  w[3] = t3 / 6.0;
}

// Segment and weights of angle theta on a periodic spline with m controls:
// controls (j + k) mod m, k = 0..3.
int Locate(double theta, int m, double w[4]) {
  const double u = WrapPositive(theta + M_PI) / kTwoPi * m;
  int j = static_cast<int>(std::floor(u));
  const double t = u - j;
  j %= m;
  Basis(t, w);
  return j;
}

double Evaluate(const Eigen::VectorXd& c, double theta) {
  const int m = static_cast<int>(c.size());
  double w[4];
  const int j = Locate(theta, m, w);
  double v = 0.0;
  for (int k = 0; k < 4; ++k) v += w[k] * c[(j + k) % m];
  return v;
}

double MedianStep(const PointList& points) {
  std::vector<double> steps;
  for (size_t i = 1; i < points.size(); ++i) {
    const double d = (points[i] - points[i - 1]).norm();
    if (d > 0 && std::isfinite(d)) steps.push_back(d);
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2), steps.end());
  return steps[steps.size() / 2];
}

// Points strictly between a and b on the segment, `spacing` apart (evenly).
PointList Segment(const Eigen::Vector3f& a, const Eigen::Vector3f& b, double spacing) {
  PointList out;
  const int n = RoundToInt((b - a).norm() / spacing, 0, std::numeric_limits<int>::max());
  for (int i = 1; i < n; ++i) out.push_back(a + (b - a) * (static_cast<float>(i) / static_cast<float>(n)));
  return out;
}

double RadiusAround(const Eigen::Vector3f& p, const Eigen::Vector2d& axis_xy) {
  return (p.head<2>().cast<double>() - axis_xy).norm();
}

void Append(HoleBoundary* b, const PointList& points) {
  for (const Eigen::Vector3f& p : points) {
    b->points_V.push_back(p);
    b->source_indices.push_back(-1);
  }
}

// Closes an open boundary with a straight segment from its last point to
// its first.
void CloseStraight(HoleBoundary* b, double spacing) {
  if (b->points_V.size() >= 2) Append(b, Segment(b->points_V.back(), b->points_V.front(), spacing));
  b->closed = true;
}

// The samples (index into `angles`) inside the counter-clockwise arc from
// `from` to `from + length`, at least the margins (angles) away from its
// ends, in the arc's order.
std::vector<size_t> SamplesInArc(const std::vector<double>& angles, double from, double length,
                                 double margin_from, double margin_to) {
  std::vector<std::pair<double, size_t>> inside;
  for (size_t k = 0; k < angles.size(); ++k) {
    const double a = WrapPositive(angles[k] - from);
    if (a > margin_from && a < length - margin_to) inside.push_back({a, k});
  }
  std::sort(inside.begin(), inside.end());
  std::vector<size_t> out;
  for (const auto& entry : inside) out.push_back(entry.second);
  return out;
}

// A gap of the missing surface's boundary (points sorted by angle): after
// the point at `before`, the counter-clockwise arc [from, from + length]
// holds no point; with the tangent lines of the boundary at both ends.
struct Gap {
  size_t before{0};
  double from{0}, length{0};
  double margin_from{0}, margin_to{0};
  Eigen::Vector2d a{0, 0}, b{0, 0};          // the ends
  Eigen::Vector2d dir_a{0, 0}, dir_b{0, 0};  // tangents (zero if unknown)
};

// Tangent direction (xy) of the points within `window` of sorted[end],
// walking away from the gap (step -1 or +1, cyclic); zero if too few.
Eigen::Vector2d Tangent(const PointList& sorted, size_t end, int step, double window) {
  const size_t n = sorted.size();
  std::vector<Eigen::Vector2d> near;
  for (size_t k = 0; k < n; ++k) {
    const long count = static_cast<long>(n);
    const long index = ((static_cast<long>(end) + step * static_cast<long>(k)) % count + count) % count;
    const Eigen::Vector3f& p = sorted[static_cast<size_t>(index)];
    if ((p - sorted[end]).norm() > window) break;
    near.emplace_back(p.x(), p.y());
  }
  if (near.size() < 3) return Eigen::Vector2d::Zero();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& q : near) mean += q;
  mean /= static_cast<double>(near.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& q : near) cov += (q - mean) * (q - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  // A clear direction only (a straight run, not a blob).
  if (eig.eigenvalues()[1] < 4.0 * eig.eigenvalues()[0]) return Eigen::Vector2d::Zero();
  return eig.eigenvectors().col(1);
}

std::vector<Gap> FindGaps(const PointList& sorted, const RimCurve& curve, double spacing, double gap_factor) {
  const size_t n = sorted.size();
  std::vector<size_t> raw;  // gap after sorted[k]
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3f& p = sorted[k];
    const Eigen::Vector3f& q = sorted[(k + 1) % n];
    const double length = WrapPositive(curve.AngleOf(q) - curve.AngleOf(p));
    const double r = 0.5 * (RadiusAround(p, curve.axis_xy()) + RadiusAround(q, curve.axis_xy()));
    if (length * r > gap_factor * spacing) raw.push_back(k);
  }
  // A few points alone inside a mouth (a claw side's top taken for rim)
  // do not split it: gaps separated by a shorter run merge.
  std::vector<std::pair<size_t, size_t>> spans;  // (last point before, first point after)
  for (size_t g = 0; g < raw.size(); ++g) {
    const size_t after = (raw[g] + 1) % n;
    if (!spans.empty() && (raw[g] + n - spans.back().second) % n < kMinRimRun) {
      spans.back().second = after;
    } else {
      spans.push_back({raw[g], after});
    }
  }
  if (spans.size() >= 2 && (spans.front().first + n - spans.back().second) % n < kMinRimRun) {
    spans.front().first = spans.back().first;
    spans.pop_back();
  }
  std::vector<Gap> gaps;
  for (const auto& [before, after] : spans) {
    const Eigen::Vector3f& p = sorted[before];
    const Eigen::Vector3f& q = sorted[after];
    Gap gap;
    gap.before = before;
    gap.from = curve.AngleOf(p);
    gap.length = WrapPositive(curve.AngleOf(q) - gap.from);
    if (gap.length == 0.0) gap.length = kTwoPi;  // one run of points only
    gap.margin_from = 0.5 * spacing / std::max(RadiusAround(p, curve.axis_xy()), 1e-6);
    gap.margin_to = 0.5 * spacing / std::max(RadiusAround(q, curve.axis_xy()), 1e-6);
    gap.a = p.head<2>().cast<double>();
    gap.b = q.head<2>().cast<double>();
    gap.dir_a = Tangent(sorted, before, -1, kTangentWindowSpacings * spacing);
    gap.dir_b = Tangent(sorted, after, +1, kTangentWindowSpacings * spacing);
    gaps.push_back(gap);
  }
  return gaps;
}

// Distance along the ray from `o` in direction `u` to the line through
// `p` with direction `d`; infinity if the ray does not meet it.
double RayToLine(const Eigen::Vector2d& o, const Eigen::Vector2d& u, const Eigen::Vector2d& p,
                 const Eigen::Vector2d& d) {
  const double den = u.x() * d.y() - u.y() * d.x();
  if (std::abs(den) < 1e-12) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d w = p - o;
  const double t = (w.x() * d.y() - w.y() * d.x()) / den;
  return t > 0 ? t : std::numeric_limits<double>::infinity();
}

// Inside each gap the rim of a convex section lies between the chord of
// the gap's ends and the tangent lines at them; the spline, which cannot
// turn a sharp corner (a cuboid's claw hole ends 0.4 mm before one), is
// clamped into that wedge. The chord bounds a gap of less than half a
// turn only: across a longer one it lies behind the axis, and a ray near
// the gap's ends meets its line far out (a ball's rim seen over 158
// degrees got samples 0.3 m away).
PointList ClampToConvexity(PointList samples, const std::vector<double>& angles, const std::vector<Gap>& gaps,
                           const RimCurve& curve) {
  const Eigen::Vector2d o = curve.axis_xy();
  for (const Gap& gap : gaps) {
    for (size_t s : SamplesInArc(angles, gap.from, gap.length, 0.0, 0.0)) {
      const Eigen::Vector2d u(std::cos(angles[s]), std::sin(angles[s]));
      double r = RadiusAround(samples[s], o);
      const double r_chord =
          gap.length < M_PI ? RayToLine(o, u, gap.a, gap.b - gap.a) : std::numeric_limits<double>::infinity();
      double r_max = std::numeric_limits<double>::infinity();
      if (gap.dir_a.squaredNorm() > 0) r_max = std::min(r_max, RayToLine(o, u, gap.a, gap.dir_a));
      if (gap.dir_b.squaredNorm() > 0) r_max = std::min(r_max, RayToLine(o, u, gap.b, gap.dir_b));
      // (A straight edge's tangents lie on its chord: the wedge is the chord.)
      if (std::isfinite(r_chord)) r_max = std::max(r_max, r_chord);
      r = std::min(r, r_max);
      if (std::isfinite(r_chord)) r = std::max(r, r_chord);
      const double x = o.x() + r * u.x(), y = o.y() + r * u.y();
      samples[s] = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y),
                                   static_cast<float>(curve.HeightAt(x, y)));
    }
  }
  return samples;
}

// A rim curve stays by its points: within their box grown by its size
// on every side (a circle's from an arc of it included). One fitted to a
// finger pad's U taken for the rim (24 points over 35 degrees, 24-40 mm
// high) tilted its plane and reached 110 mm over them: no rim.
bool WithinReach(const PointList& samples, const PointList& points) {
  Eigen::AlignedBox3f box;
  box.setEmpty();
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const Eigen::Vector3f reach = Eigen::Vector3f::Constant(box.sizes().maxCoeff());
  const Eigen::AlignedBox3f near(box.min() - reach, box.max() + reach);
  return std::all_of(samples.begin(), samples.end(),
                     [&near](const Eigen::Vector3f& p) { return near.contains(p); });
}

}  // namespace

void CompletionConfig::Validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument("CompletionConfig: " + what); };
  if (!std::isfinite(spacing_m) || spacing_m < 0.0) fail("spacing_m must be finite and >= 0");
  if (!std::isfinite(min_spacing_m) || min_spacing_m <= 0.0) fail("min_spacing_m must be finite and > 0");
  if (!std::isfinite(points_per_control_point) || points_per_control_point <= 0.0) {
    fail("points_per_control_point must be finite and > 0");
  }
  if (min_control_points < 4) fail("min_control_points must be >= 4");
  if (max_control_points < min_control_points) fail("max_control_points must be >= min_control_points");
  if (!std::isfinite(smoothing) || smoothing <= 0.0) fail("smoothing must be finite and > 0");
  if (!std::isfinite(gap_factor) || gap_factor < 1.0) fail("gap_factor must be finite and >= 1");
  if (min_fit_points < 4) fail("min_fit_points must be >= 4");
  if (!(min_coverage_rad >= 0.0 && min_coverage_rad <= kTwoPi)) fail("min_coverage_rad must be in [0, 2 pi]");
  if (!std::isfinite(max_below_rim_m) || max_below_rim_m <= 0.0)
    fail("max_below_rim_m must be finite and > 0");
  if (!std::isfinite(max_rim_distance_m) || max_rim_distance_m <= 0.0) {
    fail("max_rim_distance_m must be finite and > 0");
  }
}

std::optional<RimCurve> RimCurve::Fit(const PointList& points_in, const CompletionConfig& config,
                                      std::string* why) {
  config.Validate();
  auto fail = [why](const std::string& reason) -> std::optional<RimCurve> {
    if (why) *why = reason;
    return std::nullopt;
  };
  PointList points;
  for (const Eigen::Vector3f& p : points_in) {
    if (p.allFinite()) points.push_back(p);
  }
  int n = static_cast<int>(points.size());
  if (n < config.min_fit_points) {
    return fail("rim curve: " + std::to_string(n) + " points, at least " +
                std::to_string(config.min_fit_points) + " needed");
  }
  // The axis: V's z-axis, unless the points do not surround it; then the
  // centre of the circle fitted to them.
  RimCurve curve;
  auto max_gap = [&points](const Eigen::Vector2d& c) {
    std::vector<double> a;
    for (const Eigen::Vector3f& p : points) a.push_back(std::atan2(p.y() - c.y(), p.x() - c.x()));
    std::sort(a.begin(), a.end());
    double gap = a.front() + kTwoPi - a.back();
    for (size_t k = 1; k < a.size(); ++k) gap = std::max(gap, a[k] - a[k - 1]);
    return gap;
  };
  double gap = max_gap(curve.axis_xy_);
  if (gap > M_PI) {
    geometry::CircleFit fit;
    for (const Eigen::Vector3f& p : points) fit.Add(p.x(), p.y());
    const std::optional<Eigen::Vector2d> centre = fit.Centre();
    if (!centre) return fail("rim curve: no circle through the points");
    curve.axis_xy_ = *centre;
    gap = max_gap(curve.axis_xy_);
  }
  if (kTwoPi - gap < config.min_coverage_rad) {
    return fail("rim curve: the points cover " + std::to_string((kTwoPi - gap) * 180.0 / M_PI) +
                " degrees around the axis");
  }
  // Height: the plane of the rim (step 4 found the missing surface's
  // boundary planar). A spline in z would carry the slope of the few
  // points at a gap's edge (a claw side's top) across the gap. Points well
  // below the plane are such side points, not rim (on a sphere they also
  // stand out radially): they leave the fit.
  auto fit_plane = [&curve, &points]() {
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Vector3d atb = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3d row(1.0, p.x(), p.y());
      ata += row * row.transpose();
      atb += row * p.z();
    }
    curve.height_plane_ = ata.ldlt().solve(atb);
    return curve.height_plane_.allFinite();
  };
  if (!fit_plane()) return fail("rim curve: no plane through the points");
  {
    std::vector<double> residual;
    for (const Eigen::Vector3f& p : points) residual.push_back(p.z() - curve.HeightAt(p.x(), p.y()));
    std::vector<double> absolute(residual.size());
    for (size_t k = 0; k < residual.size(); ++k) absolute[k] = std::abs(residual[k]);
    std::nth_element(absolute.begin(), absolute.begin() + static_cast<long>(absolute.size() / 2),
                     absolute.end());
    const double sigma = 1.4826 * absolute[absolute.size() / 2];  // robust
    const double floor = -std::max(config.max_below_rim_m, 2.5 * sigma);
    PointList kept;
    for (size_t k = 0; k < points.size(); ++k) {
      if (residual[k] >= floor) kept.push_back(points[k]);
    }
    if (static_cast<int>(kept.size()) >= config.min_fit_points && kept.size() < points.size()) {
      points = std::move(kept);
      if (!fit_plane()) return fail("rim curve: no plane through the points");
    }
  }

  n = static_cast<int>(points.size());
  // Least squares with the third-difference penalty: (A'A + l D'D) c = A'y.
  const int m = std::clamp(static_cast<int>(std::lround(n / config.points_per_control_point)),
                           config.min_control_points, config.max_control_points);
  std::vector<double> theta(static_cast<size_t>(n)), radius(static_cast<size_t>(n)),
      dz(static_cast<size_t>(n));
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(m, m);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = points[static_cast<size_t>(i)];
    const double dx = p.x() - curve.axis_xy_.x(), dy = p.y() - curve.axis_xy_.y();
    theta[static_cast<size_t>(i)] = std::atan2(dy, dx);
    radius[static_cast<size_t>(i)] = std::hypot(dx, dy);
    dz[static_cast<size_t>(i)] = p.z() - curve.HeightAt(p.x(), p.y());
    double w[4];
    const int j = Locate(theta[static_cast<size_t>(i)], m, w);
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) normal((j + a) % m, (j + b) % m) += w[a] * w[b];
    }
  }
  const double lambda = config.smoothing * n / m;
  const double d3[4] = {-1.0, 3.0, -3.0, 1.0};
  for (int i = 0; i < m; ++i) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) normal((i + a) % m, (i + b) % m) += lambda * d3[a] * d3[b];
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return fail("rim curve: singular least squares");
  auto solve = [&]() {
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m);
    for (int i = 0; i < n; ++i) {
      double w[4];
      const int j = Locate(theta[static_cast<size_t>(i)], m, w);
      for (int a = 0; a < 4; ++a) rhs[(j + a) % m] += w[a] * radius[static_cast<size_t>(i)];
    }
    curve.r_ = ldlt.solve(rhs);
  };
  solve();
  // Where the wall is not vertical (a sphere's upper half flares out below
  // the cut), the band's radius depends on its height, and next to a claw
  // hole's mouth the band's low points pull the curve outwards across it.
  // The slope dr/dz of the residuals projects every point to the plane's
  // height, and the curve is fitted again.
  double zz = 0.0, zr = 0.0;
  for (int i = 0; i < n; ++i) {
    const size_t k = static_cast<size_t>(i);
    zz += dz[k] * dz[k];
    zr += dz[k] * (radius[k] - curve.Radius(theta[k]));
  }
  if (zz > 0.0 && std::abs(zr / zz) > kMinWallSlope) {
    const double slope = zr / zz;
    for (int i = 0; i < n; ++i) radius[static_cast<size_t>(i)] -= slope * dz[static_cast<size_t>(i)];
    solve();
  }
  if (!curve.r_.allFinite()) return fail("rim curve: non-finite fit");
  for (int k = 0; k < 4 * m; ++k) {
    if (curve.Radius(-M_PI + kTwoPi * k / (4 * m)) <= 0.0) return fail("rim curve: radius <= 0");
  }
  return curve;
}

double RimCurve::Radius(double theta) const { return Evaluate(r_, theta); }

double RimCurve::HeightAt(double x, double y) const {
  return height_plane_[0] + height_plane_[1] * x + height_plane_[2] * y;
}

Eigen::Vector3f RimCurve::At(double theta) const {
  const double r = Radius(theta);
  const double x = axis_xy_.x() + r * std::cos(theta), y = axis_xy_.y() + r * std::sin(theta);
  return Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(HeightAt(x, y)));
}

double RimCurve::AngleOf(const Eigen::Vector3f& p_V) const {
  return std::atan2(p_V.y() - axis_xy_.y(), p_V.x() - axis_xy_.x());
}

PointList RimCurve::Resample(double spacing_m, std::vector<double>* angles) const {
  if (!(spacing_m > 0.0)) throw std::invalid_argument("RimCurve::Resample: spacing must be > 0");
  // Arc length from a dense polyline.
  double r_max = 0.0;
  for (int i = 0; i < r_.size(); ++i) r_max = std::max(r_max, std::abs(r_[i]));
  const int dense = CeilToInt(kTwoPi * r_max / spacing_m * kDensePerSpacing, kMinDense, kMaxDense);
  std::vector<double> theta(static_cast<size_t>(dense) + 1), length(static_cast<size_t>(dense) + 1, 0.0);
  Eigen::Vector3f previous = At(-M_PI);
  for (int i = 0; i <= dense; ++i) {
    theta[static_cast<size_t>(i)] = -M_PI + kTwoPi * i / dense;
    const Eigen::Vector3f p = At(theta[static_cast<size_t>(i)]);
    if (i > 0) length[static_cast<size_t>(i)] = length[static_cast<size_t>(i) - 1] + (p - previous).norm();
    previous = p;
  }
  const double total = length.back();
  const int count = RoundToInt(total / spacing_m, 3, std::numeric_limits<int>::max());
  PointList out;
  if (angles) angles->clear();
  size_t seg = 0;
  for (int j = 0; j < count; ++j) {
    const double s = total * j / count;
    while (seg + 1 < length.size() - 1 && length[seg + 1] < s) ++seg;
    const double span = length[seg + 1] - length[seg];
    const double f = span > 0 ? (s - length[seg]) / span : 0.0;
    const double a = theta[seg] + f * (theta[seg + 1] - theta[seg]);
    out.push_back(At(a));
    if (angles) angles->push_back(a);
  }
  return out;
}

void CompleteBoundaries(std::vector<HoleBoundary>* boundaries, const CompletionConfig& config) {
  if (!boundaries) throw std::invalid_argument("CompleteBoundaries: null boundaries");
  config.Validate();
  for (const HoleBoundary& b : *boundaries) {
    if (b.source_indices.size() != b.points_V.size()) {
      throw std::invalid_argument("CompleteBoundaries: a boundary has " + std::to_string(b.points_V.size()) +
                                  " points but " + std::to_string(b.source_indices.size()) +
                                  " source indices");
    }
  }
  HoleBoundary* missing = nullptr;
  for (HoleBoundary& b : *boundaries) {
    if (b.kind == HoleKind::kMissingSurface && !b.points_V.empty()) {
      missing = &b;
      break;
    }
  }
  // Spacing: the missing surface's own, else all boundaries'.
  double spacing = config.spacing_m;
  if (spacing <= 0.0 && missing) spacing = MedianStep(missing->points_V);
  if (spacing <= 0.0) {
    PointList all;
    for (const HoleBoundary& b : *boundaries) all.insert(all.end(), b.points_V.begin(), b.points_V.end());
    spacing = MedianStep(all);
  }
  spacing = std::max(spacing, config.min_spacing_m);

  std::optional<RimCurve> curve;
  if (missing) curve = RimCurve::Fit(missing->points_V, config);
  std::vector<double> angles;
  PointList samples = curve ? curve->Resample(spacing, &angles) : PointList();
  if (curve && !WithinReach(samples, missing->points_V)) {
    curve.reset();
    samples.clear();
    angles.clear();
  }

  if (missing && curve) {
    // Order by angle, then fill the gaps with the curve's samples.
    std::vector<std::pair<double, size_t>> order;
    for (size_t k = 0; k < missing->points_V.size(); ++k) {
      order.push_back({curve->AngleOf(missing->points_V[k]), k});
    }
    std::stable_sort(order.begin(), order.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    PointList sorted;
    for (const auto& entry : order) sorted.push_back(missing->points_V[entry.second]);
    const std::vector<Gap> gaps = FindGaps(sorted, *curve, spacing, config.gap_factor);
    samples = ClampToConvexity(samples, angles, gaps, *curve);
    // The original points and the samples in the gaps (away from points
    // left inside a merged gap), by angle.
    std::vector<std::pair<double, std::pair<Eigen::Vector3f, int>>> merged;
    for (const auto& entry : order) {
      merged.push_back(
          {entry.first, {missing->points_V[entry.second], missing->source_indices[entry.second]}});
    }
    for (const Gap& gap : gaps) {
      for (size_t s : SamplesInArc(angles, gap.from, gap.length, gap.margin_from, gap.margin_to)) {
        bool crowded = false;
        for (size_t k = 0; k < sorted.size() && !crowded; ++k) {
          crowded = (sorted[k] - samples[s]).norm() < 0.5 * spacing;
        }
        if (!crowded) merged.push_back({angles[s], {samples[s], -1}});
      }
    }
    std::stable_sort(merged.begin(), merged.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    HoleBoundary filled;
    filled.kind = missing->kind;
    for (const auto& entry : merged) {
      filled.points_V.push_back(entry.second.first);
      filled.source_indices.push_back(entry.second.second);
    }
    filled.closed = true;
    *missing = std::move(filled);
  }

  for (HoleBoundary& b : *boundaries) {
    if (b.closed) continue;
    if (&b == missing) {  // no curve: straight gap fills
      HoleBoundary filled;
      filled.kind = b.kind;
      for (size_t k = 0; k < b.points_V.size(); ++k) {
        filled.points_V.push_back(b.points_V[k]);
        filled.source_indices.push_back(b.source_indices[k]);
        const Eigen::Vector3f& next = b.points_V[(k + 1) % b.points_V.size()];
        if ((next - b.points_V[k]).norm() > config.gap_factor * spacing) {
          Append(&filled, Segment(b.points_V[k], next, spacing));
        }
      }
      filled.closed = true;
      b = std::move(filled);
      continue;
    }
    if (!curve || b.points_V.size() < 2) {
      CloseStraight(&b, spacing);
      continue;
    }
    // A claw hole open at the top: along the rim across its mouth.
    const Eigen::Vector3f first = b.points_V.front(), last = b.points_V.back();
    const double a_first = curve->AngleOf(first), a_last = curve->AngleOf(last);
    const Eigen::Vector3f rim_first = curve->At(a_first), rim_last = curve->At(a_last);
    if ((rim_first - first).norm() > config.max_rim_distance_m ||
        (rim_last - last).norm() > config.max_rim_distance_m) {
      CloseStraight(&b, spacing);
      continue;
    }
    // The mouth: of the two arcs between the ends, the one holding the
    // claw's mean angle (unless that one is over half the rim).
    Eigen::Vector2d mean_dir = Eigen::Vector2d::Zero();
    for (const Eigen::Vector3f& p : b.points_V) {
      const double a = curve->AngleOf(p);
      mean_dir += Eigen::Vector2d(std::cos(a), std::sin(a));
    }
    const double a_mean = std::atan2(mean_dir.y(), mean_dir.x());
    const double ccw = WrapPositive(a_first - a_last);  // last -> first, counter-clockwise
    bool counter_clockwise = WrapPositive(a_mean - a_last) < ccw;
    if (counter_clockwise && ccw > M_PI) counter_clockwise = false;
    if (!counter_clockwise && kTwoPi - ccw > M_PI) counter_clockwise = true;
    const double m_last = 0.5 * spacing / std::max(RadiusAround(rim_last, curve->axis_xy()), 1e-6);
    const double m_first = 0.5 * spacing / std::max(RadiusAround(rim_first, curve->axis_xy()), 1e-6);
    std::vector<size_t> arc;
    if (counter_clockwise) {
      arc = SamplesInArc(angles, a_last, ccw, m_last, m_first);
    } else {
      arc = SamplesInArc(angles, a_first, kTwoPi - ccw, m_first, m_last);
      std::reverse(arc.begin(), arc.end());
    }
    if (arc.empty()) {
      CloseStraight(&b, spacing);
      continue;
    }
    // Straight connectors cover ends that lie off the curve.
    PointList closure = Segment(last, samples[arc.front()], spacing);
    for (size_t s : arc) closure.push_back(samples[s]);
    const PointList tail = Segment(samples[arc.back()], first, spacing);
    closure.insert(closure.end(), tail.begin(), tail.end());
    Append(&b, closure);
    b.closed = true;
  }
}

}  // namespace graspfill::repair
