// SPDX-License-Identifier: BSD-3-Clause
#include "virtual_frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "geometry/polygon_2d.hpp"
#include "geometry/ransac_planes.hpp"
#include "neighbor_index.hpp"

namespace graspfill::repair {
namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using geometry::FitPlaneOf;
using geometry::PlaneInliers;
using geometry::RansacPlane;
using geometry::RansacPlanes;

// A plane with at most this fraction of the cloud beyond it (strays) has
// the cloud on one side.
constexpr double kStrayFraction = 0.002;
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
               RansacPlane* plane) {
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
  if (!FitPlaneOf(boundary, rim, &n, &d)) return;
  if (n.dot(empty) < std::cos(kMaxRefineAngleRad) && -n.dot(empty) < std::cos(kMaxRefineAngleRad)) return;
  if (n.dot(plane->normal) < 0) n = -n, d = -d;
  plane->normal = n;
  plane->offset = d;
}

// Distance from `centroid` to the line through the centre of the plane's
// rim (its boundary inliers) along its normal, in units of the rim's RMS
// radius.
double AxisOffset(const std::vector<Vec3>& boundary, const RansacPlane& plane, double threshold,
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

PlaneStats MeasurePlane(const PackedCloud& cloud, const NeighborIndex& boundary_index, double support_radius,
                        const Vec3& normal, double offset, double threshold, double band) {
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
    rim += boundary_index.AnyWithin(Eigen::Vector3f(cloud.x[i], cloud.y[i], cloud.z[i]), support_radius);
  }
  stats.open_fraction = static_cast<double>(rim) / tested;
  return stats;
}

double Quantile(std::vector<double> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

geometry::RansacPlanesConfig RansacConfigOf(const VirtualFrameConfig& config) {
  geometry::RansacPlanesConfig ransac;
  ransac.distance_m = config.plane_distance_m;
  ransac.confidence = config.ransac_confidence;
  ransac.max_iterations = config.max_ransac_iterations;
  ransac.side_band_m = config.extreme_band_m;
  ransac.stray_fraction = kStrayFraction;
  ransac.hint_ring_rad = kMaxRefineAngleRad;
  ransac.seed = config.seed;
  return ransac;
}

// What every step of the plane search reads: the finite points, the
// indexes over them and the config.
struct SearchContext {
  const std::vector<Vec3>& cloud;
  const std::vector<Vec3>& boundary;
  const NeighborIndex& boundary_index;
  const PackedCloud& packed_cloud;
  const VirtualFrameConfig& config;
  std::optional<Vec3> hint;
  // Planes with fewer cloud points than this beyond one side are cuts.
  int stray_limit;
  Vec3 centroid;

  bool InHintCone(const Vec3& n) const {
    return !hint || std::abs(n.dot(*hint)) >= std::cos(config.hint_max_angle_rad);
  }
  PlaneStats Measure(const RansacPlane& p) const {
    return MeasurePlane(packed_cloud, boundary_index, config.open_support_radius_m, p.normal, p.offset,
                        config.plane_distance_m, config.extreme_band_m);
  }
  bool IsCut(const PlaneStats& st) const { return std::min(st.above, st.below) <= stray_limit; }
};

// The planes found so far, what was measured of them and which may be the
// missing-surface plane.
struct PlaneSearch {
  std::vector<PlaneStats> stats;  // one per extracted plane
  std::vector<double> axis_offset;
  std::vector<size_t> candidates;
  // Eq. 4 among the candidates only (else over every plane).
  bool eq4_of_candidates{false};
};

// Measures the planes the extractor found since the last call.
void MeasureNewPlanes(const SearchContext& ctx, const RansacPlanes& extractor,
                      std::vector<PlaneStats>* stats) {
  for (size_t k = stats->size(); k < extractor.planes().size(); ++k) {
    stats->push_back(ctx.Measure(extractor.planes()[k]));
  }
}

// Extracts cut planes, refitting the open ones to their rims, until the
// config's count, or until a clean cut square to the axis (the top) is found.
// merged[k]: plane k met an earlier one on the same rim.
void ExtractOpenCuts(const SearchContext& ctx, RansacPlanes* extractor, PlaneSearch* search,
                     std::vector<char>* merged) {
  const VirtualFrameConfig& config = ctx.config;
  std::vector<PlaneStats>& stats = search->stats;
  while (static_cast<int>(extractor->planes().size()) < config.max_planes &&
         extractor->FindNext(RansacPlanes::Mode::kCut)) {
    MeasureNewPlanes(ctx, *extractor, &stats);
    const size_t k = stats.size() - 1;
    merged->push_back(0);
    // Only planes that could be the top are worth the refit.
    if (stats[k].open_fraction < kMinRefineOpenFraction) continue;
    RansacPlane& p = extractor->mutable_plane(k);
    const bool empty_above = stats[k].above <= stats[k].below;
    RefineCut(ctx.boundary, config.plane_distance_m, empty_above ? p.normal : Vec3(-p.normal), &p);
    stats[k] = ctx.Measure(p);
    // Two refits that met on the same rim are one plane.
    for (size_t i = 0; i < k && !(*merged)[k]; ++i) {
      const RansacPlane& a = extractor->planes()[i];
      const double c = a.normal.dot(p.normal);
      (*merged)[k] = !(*merged)[i] && std::abs(c) >= std::cos(kMaxRefineAngleRad / 2) &&
                     std::abs(a.offset - (c > 0 ? p.offset : -p.offset)) <= 2.0 * config.plane_distance_m;
    }
    // A clean cut square to the axis is the top: no other plane could
    // beat it below, so the search stops (saving the rounds after it).
    if (!(*merged)[k] && ctx.IsCut(stats[k]) && stats[k].open_fraction >= 1.0 - config.open_fraction_tie &&
        ctx.InHintCone(p.normal)) {
      search->axis_offset[k] = AxisOffset(ctx.boundary, p, config.plane_distance_m, ctx.centroid);
      if (search->axis_offset[k] <= config.axis_offset_tie) break;
    }
  }
}

// Keeps the candidates whose score is within `tie` of the best (highest
// when `highest`, else lowest).
std::vector<size_t> WithinTie(const std::vector<size_t>& candidates, const std::vector<double>& score,
                              double tie, bool highest) {
  double best = highest ? 0.0 : std::numeric_limits<double>::infinity();
  for (size_t k : candidates) best = highest ? std::max(best, score[k]) : std::min(best, score[k]);
  std::vector<size_t> kept;
  for (size_t k : candidates) {
    if (highest ? score[k] >= best - tie : score[k] <= best + tie) kept.push_back(k);
  }
  return kept;
}

// The best-mode search: open cuts refitted to their rims; the most open;
// the one square to the symmetry axis; Eq. 4 among those still tied; the
// inlier count. (Eq. 4 alone fails on an ellipsoid: the claw planes on its
// two flatter sides are orthogonal to the one on its end.)
void SearchOpenCuts(const SearchContext& ctx, RansacPlanes* extractor, PlaneSearch* search) {
  const VirtualFrameConfig& config = ctx.config;
  const std::vector<PlaneStats>& stats = search->stats;
  std::vector<char> merged;
  ExtractOpenCuts(ctx, extractor, search, &merged);
  std::vector<size_t> candidates;
  for (size_t k = 0; k < stats.size(); ++k) {
    if (!merged[k] && ctx.IsCut(stats[k]) && stats[k].open_fraction >= config.min_open_fraction &&
        ctx.InHintCone(extractor->planes()[k].normal)) {
      candidates.push_back(k);
    }
  }
  // The cleanest cut: the top was cut by a plane (and its plane refitted
  // to the rim), while a claw hole's outline is planar only on a planar
  // face, which is no cut, and close to a plane on a curved one (a
  // sphere: 0.7-0.8 open).
  std::vector<double> open_fraction(stats.size());
  for (size_t k = 0; k < stats.size(); ++k) open_fraction[k] = stats[k].open_fraction;
  candidates = WithinTie(candidates, open_fraction, config.open_fraction_tie, true);
  // Then the one square to the symmetry axis: the normal through the
  // cut's centre passes through the cloud's centroid. (A plane that only
  // touches the rim from aside is as open, but tilted off the axis.)
  for (size_t k : candidates) {
    search->axis_offset[k] =
        AxisOffset(ctx.boundary, extractor->planes()[k], config.plane_distance_m, ctx.centroid);
  }
  search->candidates = WithinTie(candidates, search->axis_offset, config.axis_offset_tie, false);
  search->eq4_of_candidates = true;
}

// The paper's search: planes each taking the points no earlier one
// explains, Eq. 4 over all of them (those in the hint's cone, if any is).
void SearchPaperPlanes(const SearchContext& ctx, RansacPlanes* extractor, PlaneSearch* search) {
  const size_t first = extractor->planes().size();
  while (static_cast<int>(extractor->planes().size() - first) < ctx.config.max_planes &&
         extractor->FindNext(RansacPlanes::Mode::kFresh)) {
  }
  MeasureNewPlanes(ctx, *extractor, &search->stats);
  for (size_t k = first; k < extractor->planes().size(); ++k) {
    if (ctx.InHintCone(extractor->planes()[k].normal)) search->candidates.push_back(k);
  }
  if (search->candidates.empty()) {
    for (size_t k = first; k < extractor->planes().size(); ++k) search->candidates.push_back(k);
  }
  search->eq4_of_candidates = false;
}

// The report of every extracted plane, Eq. 4's sum over all of them included.
std::vector<BoundaryPlane> DescribePlanes(const SearchContext& ctx, const std::vector<RansacPlane>& extracted,
                                          const PlaneSearch& search) {
  std::vector<BoundaryPlane> planes(extracted.size());
  for (size_t k = 0; k < planes.size(); ++k) {
    planes[k].normal = extracted[k].normal;
    planes[k].offset = extracted[k].offset;
    planes[k].inliers = extracted[k].inliers;
    planes[k].open_fraction = search.stats[k].open_fraction;
    planes[k].cut = ctx.IsCut(search.stats[k]);
    planes[k].axis_offset = search.axis_offset[k];
    for (size_t i = 0; i < planes.size(); ++i) {
      if (i != k) planes[k].eq4_sum += std::abs(extracted[k].normal.dot(extracted[i].normal));
    }
  }
  return planes;
}

// Eq. 4: the candidate most orthogonal to the others (the lowest sum of
// |n . n_i|); among those within the tolerance, the most inliers.
size_t ChoosePlane(const std::vector<BoundaryPlane>& planes, const PlaneSearch& search,
                   double eq4_tie_tolerance) {
  const std::vector<size_t>& candidates = search.candidates;
  std::vector<double> sums(planes.size());
  for (size_t k : candidates) {
    if (!search.eq4_of_candidates) {
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
    if (sums[k] <= min_sum + eq4_tie_tolerance && planes[k].inliers > chosen_inliers) {
      chosen = k;
      chosen_inliers = planes[k].inliers;
    }
  }
  return chosen;
}

// Least-squares refit (two rounds) on every boundary point near the plane.
void RefitToBoundary(const std::vector<Vec3>& boundary, double plane_distance, Vec3* n, double* d) {
  std::vector<int> all_boundary(boundary.size());
  for (size_t i = 0; i < boundary.size(); ++i) all_boundary[i] = static_cast<int>(i);
  for (int round = 0; round < 2; ++round) {
    Vec3 n_ls;
    double d_ls;
    if (!FitPlaneOf(boundary, PlaneInliers(boundary, all_boundary, *n, *d, plane_distance), &n_ls, &d_ls)) {
      break;
    }
    if (n_ls.dot(*n) < 0) n_ls = -n_ls, d_ls = -d_ls;
    *n = n_ls, *d = d_ls;
  }
}

// Without a hint: when the boundary lies well off the centroid and the
// chosen plane is tilted off that direction, the direction replaces it
// (and serves as the hint). See max_boundary_axis_angle_rad.
std::optional<Vec3> AxisTowardBoundary(const SearchContext& ctx, const Vec3& n) {
  const VirtualFrameConfig& config = ctx.config;
  if (ctx.hint || config.max_boundary_axis_angle_rad <= 0.0) return std::nullopt;
  Vec3 boundary_mean = Vec3::Zero();
  Eigen::AlignedBox3d cloud_box;
  for (const Vec3& b : ctx.boundary) boundary_mean += b;
  for (const Vec3& p : ctx.cloud) cloud_box.extend(p);
  const Vec3 toward = boundary_mean / static_cast<double>(ctx.boundary.size()) - ctx.centroid;
  const double offset = toward.norm() / std::max(cloud_box.sizes().norm(), 1e-300);
  if (offset >= config.min_boundary_offset &&
      std::abs(n.dot(toward.normalized())) < std::cos(config.max_boundary_axis_angle_rad)) {
    return toward.normalized();
  }
  return std::nullopt;
}

// The sign of z (+1 or -1 times n): towards the missing surface. `heights`:
// n . p of every cloud point; `st`: the chosen plane's stats (the refit
// keeps the normal's sign, so above and below still apply).
double UpSign(const SearchContext& ctx, const std::optional<Vec3>& hint, const Vec3& n, double d,
              const PlaneStats& st, const std::vector<double>& heights) {
  const bool empty_above = st.above <= ctx.stray_limit;
  const bool empty_below = st.below <= ctx.stray_limit;
  if (hint && std::abs(n.dot(*hint)) > 1e-6) return n.dot(*hint) > 0 ? 1.0 : -1.0;
  // The cloud lies on one side of the plane: it was cut there.
  if (empty_above != empty_below) return empty_above ? 1.0 : -1.0;
  // Else the end of the cloud the boundary crowds at (the open rim).
  const double lo = Quantile(heights, kStrayFraction);
  const double hi = Quantile(heights, 1.0 - kStrayFraction);
  int near_hi = 0, near_lo = 0;
  for (const Vec3& b : ctx.boundary) {
    const double h = n.dot(b);
    near_hi += h >= hi - ctx.config.extreme_band_m;
    near_lo += h <= lo + ctx.config.extreme_band_m;
  }
  if (near_hi != near_lo) return near_hi > near_lo ? 1.0 : -1.0;
  double mean = 0.0;
  for (double h : heights) mean += h;
  return d >= mean / static_cast<double>(heights.size()) ? 1.0 : -1.0;
}

// Steps 4-5: x, y from the minimum-area rectangle of the cloud projected
// along z; the origin at the rectangle's centre, at the cloud's lowest z.
VirtualFrame FrameAroundAxis(const std::vector<Vec3>& cloud, const Vec3& z, double sign,
                             const std::vector<double>& heights, int hull_columns) {
  const Vec3 seed_axis = std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = (seed_axis - z * z.dot(seed_axis)).normalized();
  const Vec3 v = z.cross(u);
  std::vector<Vec2> projected(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) projected[i] = Vec2(u.dot(cloud[i]), v.dot(cloud[i]));
  const geometry::Rect2 rect = geometry::MinAreaRect(geometry::ApproxHull2d(projected, hull_columns));
  Vec3 x = rect.axis.x() * u + rect.axis.y() * v;
  int largest = 0;
  x.cwiseAbs().maxCoeff(&largest);
  if (x[largest] < 0) x = -x;
  const Vec3 y = z.cross(x);

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
  return frame;
}

}  // namespace

void VirtualFrameConfig::Validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument("VirtualFrameConfig: " + what); };
  auto positive = [&](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) fail(std::string(name) + " must be finite and > 0");
  };
  positive(plane_distance_m, "plane_distance_m");
  positive(open_support_radius_m, "open_support_radius_m");
  positive(extreme_band_m, "extreme_band_m");
  if (max_planes < 1) fail("max_planes must be >= 1");
  if (min_plane_inliers < 3) fail("min_plane_inliers must be >= 3");
  if (!(min_plane_fraction >= 0.0 && min_plane_fraction < 1.0)) fail("min_plane_fraction must be in [0, 1)");
  if (max_ransac_iterations < 1) fail("max_ransac_iterations must be >= 1");
  if (!(ransac_confidence > 0.0 && ransac_confidence < 1.0)) fail("ransac_confidence must be in (0, 1)");
  if (!(min_open_fraction >= 0.0 && min_open_fraction <= 1.0)) fail("min_open_fraction must be in [0, 1]");
  if (!(open_fraction_tie >= 0.0 && open_fraction_tie <= 1.0)) fail("open_fraction_tie must be in [0, 1]");
  if (!(axis_offset_tie >= 0.0) || !std::isfinite(axis_offset_tie))
    fail("axis_offset_tie must be finite and >= 0");
  if (!(eq4_tie_tolerance >= 0.0) || !std::isfinite(eq4_tie_tolerance))
    fail("eq4_tie_tolerance must be finite and >= 0");
  if (!(hint_max_angle_rad > 0.0 && hint_max_angle_rad <= M_PI / 2))
    fail("hint_max_angle_rad must be in (0, pi/2]");
  if (!(max_boundary_axis_angle_rad >= 0.0 && max_boundary_axis_angle_rad <= M_PI / 2))
    fail("max_boundary_axis_angle_rad must be in [0, pi/2]");
  if (!(min_boundary_offset >= 0.0) || !std::isfinite(min_boundary_offset))
    fail("min_boundary_offset must be finite and >= 0");
  if (hull_columns < 2) fail("hull_columns must be >= 2");
}

std::optional<VirtualFrame> EstimateVirtualFrame(const PointList& cloud_in, const PointList& boundary_in,
                                                 const VirtualFrameConfig& config,
                                                 const Eigen::Vector3d* up_hint, std::string* failure_reason,
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
  const int min_inliers =
      std::max(config.min_plane_inliers,
               static_cast<int>(std::ceil(config.min_plane_fraction * static_cast<double>(boundary.size()))));
  if (static_cast<int>(boundary.size()) < min_inliers) {
    return fail("virtual frame: " + std::to_string(boundary.size()) +
                " finite boundary points, a plane needs " + std::to_string(min_inliers));
  }
  std::optional<Vec3> hint;
  if (up_hint && up_hint->allFinite() && up_hint->norm() > 0) hint = up_hint->normalized();
  PointList boundary_f;  // the finite boundary points, as given
  for (const Vec3& b : boundary) boundary_f.push_back(b.cast<float>());
  const NeighborIndex boundary_index(boundary_f);
  const PackedCloud packed_cloud(cloud);
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : cloud) centroid += p;
  centroid /= static_cast<double>(cloud.size());
  const SearchContext ctx{cloud,
                          boundary,
                          boundary_index,
                          packed_cloud,
                          config,
                          hint,
                          static_cast<int>(kStrayFraction * static_cast<double>(cloud.size())),
                          centroid};

  // 1.-2. The missing-surface plane.
  RansacPlanes extractor(boundary, cloud, RansacConfigOf(config), min_inliers, hint);
  PlaneSearch search;
  search.axis_offset.assign(2 * static_cast<size_t>(config.max_planes), -1.0);
  if (config.prefer_open_planes) SearchOpenCuts(ctx, &extractor, &search);
  if (search.candidates.empty()) SearchPaperPlanes(ctx, &extractor, &search);
  if (search.candidates.empty()) {
    return fail("virtual frame: no plane with " + std::to_string(min_inliers) + " of the " +
                std::to_string(boundary.size()) + " boundary points within " +
                std::to_string(config.plane_distance_m) + " m");
  }
  std::vector<BoundaryPlane> planes = DescribePlanes(ctx, extractor.planes(), search);
  const size_t chosen = ChoosePlane(planes, search, config.eq4_tie_tolerance);
  planes[chosen].chosen = true;
  Vec3 n = planes[chosen].normal;
  double d = planes[chosen].offset;
  RefitToBoundary(boundary, config.plane_distance_m, &n, &d);

  // 2b. The chosen plane against where the boundary lies (see the config).
  if (const std::optional<Vec3> toward = AxisTowardBoundary(ctx, n)) {
    n = *toward;
    hint = n;
  }

  // 3. The sign of z: towards the missing surface.
  std::vector<double> heights(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) heights[i] = n.dot(cloud[i]);
  const double sign = UpSign(ctx, hint, n, d, search.stats[chosen], heights);

  // 4.-5. x, y and the origin.
  VirtualFrame frame = FrameAroundAxis(cloud, sign * n, sign, heights, config.hull_columns);
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
