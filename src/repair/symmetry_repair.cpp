// SPDX-License-Identifier: BSD-3-Clause
#include "symmetry_repair.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "clamped_int.hpp"
#include "geometry/gap_grid.hpp"
#include "graspfill/core/require.hpp"
#include "sampling_gaps.hpp"
#include "slab_profile.hpp"

namespace graspfill::repair {
namespace {

using Point2 = Eigen::Vector2d;
using Polygon = std::vector<Point2>;  // convex, counter-clockwise

void CheckFinite(const PointList& points, const char* what) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument(std::string("RepairMissingSurface: non-finite coordinate in ") + what +
                                  " at index " + std::to_string(i));
    }
  }
}

std::string Mm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f mm", m * 1e3);
  return buf;
}

// The outline of a cross-section, described by the support function of
// its convex hull, h(theta) = max over the hull of (v - centre) . u(theta),
// at kDirections directions. A claw hole dents h only over the ~40 degrees
// it faces, so statistics over the directions (a median, the upper part)
// see the object, not its holes; the hull's area would lose a few percent.
constexpr int kDirections = 72;
using Support = std::array<double, kDirections>;

const std::array<Point2, kDirections>& Directions() {
  static const std::array<Point2, kDirections> dirs = [] {
    std::array<Point2, kDirections> d;
    for (int j = 0; j < kDirections; ++j) {
      const double a = 2.0 * M_PI * j / kDirections;
      d[j] = Point2(std::cos(a), std::sin(a));
    }
    return d;
  }();
  return dirs;
}

// The hull is convex and counter-clockwise, so the vertex extreme in a
// direction moves forward as the direction turns: one pass around it.
Support SupportFunction(const Polygon& hull, const Point2& centre) {
  const std::array<Point2, kDirections>& dirs = Directions();
  const size_t n = hull.size();
  size_t k = 0;
  for (size_t i = 1; i < n; ++i) {
    if (hull[i].dot(dirs[0]) > hull[k].dot(dirs[0])) k = i;
  }
  Support h;
  size_t steps = 0;
  for (int j = 0; j < kDirections; ++j) {
    while (steps < 2 * n && hull[(k + 1) % n].dot(dirs[j]) > hull[k].dot(dirs[j])) {
      k = (k + 1) % n;
      ++steps;
    }
    h[j] = (hull[k] - centre).dot(dirs[j]);
  }
  return h;
}

// Size of a cross-section relative to a reference outline: the squared
// median, over the directions, of the ratio of their support functions
// (each about its own centroid). For sections of one shape at different
// scales (a sphere, an ellipsoid, a cone) it is the squared scale, so it
// tracks the area; a claw hole dents some directions, and up to half of
// them leave the median unchanged (the hull's area, by contrast, loses a
// few percent, which moved the plane of an ellipsoid by ~1.3 mm).
double SectionSize(const Polygon& hull, const Support& reference) {
  if (hull.size() < 3) return 0.0;
  const Support h = SupportFunction(hull, geometry::PolygonCentroid(hull));
  std::array<double, kDirections> ratio;
  for (int j = 0; j < kDirections; ++j) {
    ratio[j] = reference[j] > 0.0 ? h[j] / reference[j] : 0.0;
  }
  std::nth_element(ratio.begin(), ratio.begin() + kDirections / 2, ratio.end());
  const double r = ratio[kDirections / 2];
  return r * r;
}

// How much two outlines differ: the median over the directions of the
// difference of their support functions about their common centre,
// relative to their mean support. 0 for identical outlines; ~0.17 for a
// square and the same square turned by 45 degrees; a lateral shift counts.
double OutlineMismatch(const Polygon& a, const Polygon& b) {
  if (a.size() < 3 || b.size() < 3) return 1.0;
  const Point2 centre = 0.5 * (geometry::PolygonCentroid(a) + geometry::PolygonCentroid(b));
  const Support ha = SupportFunction(a, centre), hb = SupportFunction(b, centre);
  std::array<double, kDirections> diff;
  double mean = 0.0;
  for (int j = 0; j < kDirections; ++j) {
    diff[j] = std::abs(ha[j] - hb[j]);
    mean += 0.5 * (ha[j] + hb[j]) / kDirections;
  }
  std::nth_element(diff.begin(), diff.begin() + kDirections / 2, diff.end());
  return mean > 0.0 ? diff[kDirections / 2] / mean : 1.0;
}

// The size of every slab's outline (0: too few points) relative to the
// outline at the median height, or the nearest slab with enough points;
// false when no slab has enough. first/last (optional): the first and
// last slabs with a size.
bool SectionSizes(const SlabProfile& profile, int median_slab, int min_points, std::vector<double>* size,
                  int* first_valid = nullptr, int* last_valid = nullptr) {
  const int slabs = profile.count();
  std::vector<Polygon> hulls(slabs);
  for (int k = 0; k < slabs; ++k) hulls[k] = profile.Hull(k, min_points);
  int ref = -1;
  for (int off = 0; off < slabs && ref < 0; ++off) {
    if (median_slab + off < slabs && hulls[median_slab + off].size() >= 3)
      ref = median_slab + off;
    else if (median_slab - off >= 0 && hulls[median_slab - off].size() >= 3)
      ref = median_slab - off;
  }
  if (ref < 0) return false;
  const Support reference = SupportFunction(hulls[ref], geometry::PolygonCentroid(hulls[ref]));
  size->assign(slabs, 0.0);
  int first = -1, last = -1;
  for (int k = 0; k < slabs; ++k) {
    (*size)[k] = SectionSize(hulls[k], reference);
    if ((*size)[k] > 0.0) {
      if (first < 0) first = k;
      last = k;
    }
  }
  if (first_valid != nullptr) *first_valid = first;
  if (last_valid != nullptr) *last_valid = last;
  return true;
}

// How many of the slabs with a size are within `tolerance` of their
// median size (near), of how many (valid).
void CountNearMedian(const std::vector<double>& size, double tolerance, int* near, int* valid) {
  std::vector<double> sizes;
  for (double v : size)
    if (v > 0.0) sizes.push_back(v);
  *near = 0;
  *valid = static_cast<int>(sizes.size());
  if (sizes.empty()) return;
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<long>(sizes.size() / 2), sizes.end());
  const double median_size = sizes[sizes.size() / 2];
  for (double v : sizes) *near += std::abs(v - median_size) <= tolerance * median_size;
}

// The size profile (slab k centred at z0 + (k + 0.5) h; 0 = no data) at
// height z, linearly interpolated; NaN outside the data.
double SizeAt(const std::vector<double>& size, double z0, double h, double z) {
  const double x = (z - z0) / h - 0.5;
  const int k = FloorToInt(x, -1, static_cast<int>(size.size()));
  if (k < 0 || k + 1 >= static_cast<int>(size.size())) return std::nan("");
  if (size[k] <= 0.0 || size[k + 1] <= 0.0) return std::nan("");
  const double f = x - k;
  return (1.0 - f) * size[k] + f * size[k + 1];
}

// The plane within `half_width` of `z_guess` about which the size profile
// is most symmetric: least mean squared difference between the sizes at
// z_s + t and z_s - t over every t (in slab steps) observed on both sides;
// searched in quarter slabs, then refined by a parabola through the best
// three.
double RefinePlane(const std::vector<double>& size, double z0, double h, double z_guess, double half_width) {
  const auto cost = [&](double zs) {
    double sum = 0.0;
    int n = 0;
    for (double t = h;; t += h) {
      const double up = SizeAt(size, z0, h, zs + t), dn = SizeAt(size, z0, h, zs - t);
      if (std::isnan(up) || std::isnan(dn)) break;
      sum += (up - dn) * (up - dn);
      ++n;
    }
    return n >= 3 ? sum / n : std::numeric_limits<double>::infinity();
  };
  const double step = 0.25 * h;
  const int steps = static_cast<int>(std::ceil(half_width / step));
  double best_z = z_guess, best = cost(z_guess);
  for (int i = -steps; i <= steps; ++i) {
    const double zs = z_guess + i * step;
    const double c = cost(zs);
    if (c < best) best = c, best_z = zs;
  }
  if (!std::isfinite(best)) return z_guess;
  const double cm = cost(best_z - step), cp = cost(best_z + step);
  const double denom = cm - 2.0 * best + cp;
  if (std::isfinite(cm) && std::isfinite(cp) && denom > 0.0) {
    best_z += 0.5 * step * (cm - cp) / denom;
  }
  return best_z;
}

// Moves the image's points radially onto the observed walls. On a polar
// grid over V's axis (the slabs of h above z_s, `sectors` sectors), each
// cell fits the image of every point there as a radius r = a + b z + c t
// (z, t: height and angle about the cell's centre), and its observed
// points' median radius above that surface, each at its own height and
// angle, is the cell's offset (a hole or the cut taking part of a cell
// then biases nothing). Cells where the wall leans more than 45 degrees
// off vertical (|b| > 1) give none: there a radius tells little. A kept
// image point moves by the mean offset of the cells within `reach` of its
// own. The mirror of a leaning fruit's lower half lies 2-3 mm inside its
// upper shoulders on one side; on a symmetric object the offsets are the
// noise's, ~0.
void FitImageToObserved(const PointList& observed, const PointList& all, double z_s, double h, double z_top,
                        const SymmetryConfig& config, PointList* image) {
  const int sectors = config.fit_sectors;
  // No fit over a span of more than kMaxProfileSlabs (a stray far above).
  const int slabs = CeilToInt((z_top - z_s) / h, 0, kMaxProfileSlabs + 1);
  if (sectors <= 0 || slabs <= 0 || slabs > kMaxProfileSlabs || image->empty()) return;
  const double sector = 2.0 * M_PI / sectors;
  struct Polar {
    int cell{-1};
    double z{0.0}, t{0.0}, r{0.0};  // about the cell's centre
  };
  const auto polar = [&](double x, double y, double z) {
    Polar p;
    const int k = FloorToInt((z - z_s) / h, -1, slabs);
    if (k < 0 || k >= slabs) return p;
    const double angle = std::atan2(y, x) + M_PI;
    const int s = std::clamp(static_cast<int>(std::floor(angle / sector)), 0, sectors - 1);
    p.cell = k * sectors + s;
    p.z = z - (z_s + (k + 0.5) * h);
    p.t = angle - (s + 0.5) * sector;
    p.r = std::hypot(x, y);
    return p;
  };
  const size_t cells = static_cast<size_t>(slabs) * static_cast<size_t>(sectors);
  // The image's least squares per cell: normal equations of (1, z, t).
  std::vector<Eigen::Matrix3d> ata(cells, Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> atr(cells, Eigen::Vector3d::Zero());
  std::vector<int> image_count(cells, 0);
  for (const Eigen::Vector3f& p : all) {
    const Polar q = polar(p.x(), p.y(), 2.0 * z_s - p.z());
    if (q.cell < 0) continue;
    const Eigen::Vector3d row(1.0, q.z, q.t);
    ata[static_cast<size_t>(q.cell)] += row * row.transpose();
    atr[static_cast<size_t>(q.cell)] += row * q.r;
    ++image_count[static_cast<size_t>(q.cell)];
  }
  constexpr int kMinImagePoints = 8;
  std::vector<Eigen::Vector3d> surface(cells,
                                       Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (size_t c = 0; c < cells; ++c) {
    if (image_count[c] < kMinImagePoints) continue;
    const Eigen::LDLT<Eigen::Matrix3d> solve(ata[c]);
    if (solve.info() != Eigen::Success || !(solve.rcond() > 1e-9)) continue;
    const Eigen::Vector3d abc = solve.solve(atr[c]);
    if (abc.allFinite() && std::abs(abc.y()) <= 1.0) surface[c] = abc;
  }
  std::vector<std::vector<double>> above(cells);  // observed radius - image surface's
  for (const Eigen::Vector3f& p : observed) {
    const Polar q = polar(p.x(), p.y(), p.z());
    if (q.cell < 0 || std::isnan(surface[static_cast<size_t>(q.cell)].x())) continue;
    above[static_cast<size_t>(q.cell)].push_back(
        q.r - surface[static_cast<size_t>(q.cell)].dot(Eigen::Vector3d(1.0, q.z, q.t)));
  }
  constexpr size_t kMinObservedPoints = 3;
  std::vector<double> offset(cells, std::numeric_limits<double>::quiet_NaN());
  for (size_t c = 0; c < cells; ++c) {
    std::vector<double>& d = above[c];
    if (d.size() < kMinObservedPoints) continue;
    std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
    if (std::abs(d[d.size() / 2]) <= config.fit_max_offset_m) offset[c] = d[d.size() / 2];
  }
  const int reach = config.fit_reach_cells;
  for (Eigen::Vector3f& p : *image) {
    const Polar q = polar(p.x(), p.y(), p.z());
    if (q.cell < 0 || !(q.r > 0.0)) continue;
    const int k = q.cell / sectors, s = q.cell % sectors;
    double sum = 0.0;
    int n = 0;
    for (int dk = -reach; dk <= reach; ++dk) {
      if (k + dk < 0 || k + dk >= slabs) continue;
      for (int ds = -reach; ds <= reach; ++ds) {
        const double d = offset[static_cast<size_t>((k + dk) * sectors + (s + ds + sectors) % sectors)];
        if (!std::isnan(d)) sum += d, ++n;
      }
    }
    if (n == 0) continue;
    const double scale = std::max(0.0, q.r + sum / n) / q.r;
    p.x() = static_cast<float>(p.x() * scale);
    p.y() = static_cast<float>(p.y() * scale);
  }
}

SymmetryResult NotSymmetric(std::string reason, double plane_z) {
  SymmetryResult r;
  r.symmetric = false;
  r.reason = std::move(reason);
  r.symmetry_plane_z = plane_z;
  return r;
}

void CheckSymmetryInputs(const PointList& points_V, const HoleBoundary& missing_surface,
                         const SymmetryConfig& config, const NeighborIndex* index_V,
                         const PointList* added_before_V) {
  config.Validate();
  CheckFinite(points_V, "the cloud");
  CheckFinite(missing_surface.points_V, "the missing-surface boundary");
  if (added_before_V != nullptr) CheckFinite(*added_before_V, "the points added before");
  if (index_V != nullptr) {
    Require(&index_V->points() == &points_V,
            "RepairMissingSurface: the neighbour index must be built over the same cloud");
  }
}

// The cloud and the earlier fills together; empty when there are none
// (the cloud is used alone).
PointList WithEarlierFills(const PointList& points_V, const PointList* added_before_V) {
  PointList merged;
  if (added_before_V != nullptr && !added_before_V->empty()) {
    merged.reserve(points_V.size() + added_before_V->size());
    merged = points_V;
    merged.insert(merged.end(), added_before_V->begin(), added_before_V->end());
  }
  return merged;
}

// The heights the profile spans: the boundary's, the lowest point's and
// the median, and the boundary's box.
struct Heights {
  double z_b{0.0};
  double z_min{0.0};
  double z_median{0.0};
  Eigen::AlignedBox3f boundary_box{};
};

Heights HeightsOf(const HoleBoundary& missing_surface, const PointList& all) {
  Heights heights;
  // The boundary's height: a high quantile of its points' z (the rim is
  // the top of the observed surface; a boundary band's median would sit
  // half its width lower), robust to a stray point of the completion.
  std::vector<double> boundary_z;
  heights.boundary_box.setEmpty();
  for (const Eigen::Vector3f& p : missing_surface.points_V) {
    boundary_z.push_back(p.z());
    heights.boundary_box.extend(p);
  }
  const size_t q90 = (boundary_z.size() - 1) * 9 / 10;
  std::nth_element(boundary_z.begin(), boundary_z.begin() + static_cast<long>(q90), boundary_z.end());
  heights.z_b = boundary_z[q90];
  double z_min = std::numeric_limits<double>::infinity();
  std::vector<double> zs(all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    zs[i] = all[i].z();
    z_min = std::min(z_min, zs[i]);
  }
  heights.z_min = z_min;
  std::nth_element(zs.begin(), zs.begin() + static_cast<long>(zs.size() / 2), zs.end());
  heights.z_median = zs[zs.size() / 2];
  return heights;
}

// The cross-section profile between the bottom and the boundary: slabs of
// h, the median height's slab, every slab's size relative to it.
struct Sections {
  double z_min{0.0}, z_b{0.0}, h{0.0};
  int slabs{0};
  int median_slab{0};
  std::vector<double> size{};
  int first_valid{-1}, last_valid{-1};
};

// The symmetry plane and how it was found.
struct Plane {
  double z_s{0.0};
  std::string how{};
  bool constant_section{false};
};

// Prism-like (cuboid, prisms, cylinders): nearly every slab has the
// median slab's size. The largest section can then be anywhere (a fused
// cloud's claw fills bulge the top slabs by 15%), and the middle of the
// observed height is the plane: the mirror closes the object at the rim.
// Asked of the observed points alone: a fill ~1 mm proud of a box's
// narrow face moves the outline's corners, so every direction (a box's
// sections by the claw 3-9% larger with the fills: a plane tens of mm
// too high), while a claw hole's dent is only in the directions it
// faces, which the median over them ignores.
std::optional<Plane> PrismPlane(const PointList& points_V, bool with_fills, const Sections& sec,
                                const SymmetryConfig& config) {
  int near_median = 0, valid = 0;
  if (!with_fills) {
    CountNearMedian(sec.size, config.plateau_tolerance, &near_median, &valid);
  } else {
    std::vector<double> observed;
    if (SectionSizes(SlabProfile(points_V, sec.z_min, sec.h, sec.slabs), sec.median_slab,
                     config.min_slab_points, &observed)) {
      CountNearMedian(observed, config.plateau_tolerance, &near_median, &valid);
    }
  }
  const bool prism_like = config.plateau_search && valid > 0 && near_median >= config.prism_fraction * valid;
  if (!prism_like) return std::nullopt;
  return Plane{0.5 * (sec.z_min + sec.z_b),
               "constant cross-section (" + std::to_string(near_median) + " of " + std::to_string(valid) +
                   " slabs within " +
                   std::to_string(static_cast<int>(std::lround(100 * config.plateau_tolerance))) +
                   "% of the median): plane at mid-height",
               true};
}

// The plane in the run of near-largest slabs nearest the median slab.
Plane PlateauPlane(const Sections& sec, const SymmetryConfig& config) {
  const std::vector<double>& size = sec.size;
  const int slabs = sec.slabs, median_slab = sec.median_slab;
  const double z_min = sec.z_min, h = sec.h;
  const double s_max = *std::max_element(size.begin(), size.end());
  const double s_min = (1.0 - config.plateau_tolerance) * s_max;
  // Runs of near-largest slabs; the one nearest the median slab wins.
  int best_first = -1, best_last = -1, best_dist = std::numeric_limits<int>::max();
  for (int k = 0; k < slabs;) {
    if (size[k] < s_min) {
      ++k;
      continue;
    }
    int e = k;
    while (e + 1 < slabs && size[e + 1] >= s_min) ++e;
    const int dist = median_slab < k ? k - median_slab : (median_slab > e ? median_slab - e : 0);
    if (dist < best_dist) best_first = k, best_last = e, best_dist = dist;
    k = e + 1;
  }
  // The end slabs straddle the bottom edge and the rim, whose outlines
  // are the least certain (the protocol's 7 cm cuboid: 0.935 at the
  // bottom against 1.000 +- 0.005 above): the run may miss them.
  const int slack = config.end_slack_slabs;
  if (best_first <= sec.first_valid + slack && best_last >= sec.last_valid - slack) {
    // Constant section over the whole observed height (prism-like): the
    // middle of the observed height, i.e. the mirror closes the object at
    // the boundary.
    return Plane{0.5 * (z_min + sec.z_b),
                 "constant cross-section from bottom to boundary: plane at mid-height", true};
  }
  // The run's middle, refined to the plane about which the size profile
  // is most symmetric: the run's ends are where the profile is flat, so
  // a 1% dent moves them by ~1 mm on an ellipsoid, while the steep
  // flanks of the profile pin the plane down.
  Plane plane;
  plane.z_s = RefinePlane(size, z_min, h, z_min + 0.5 * (best_first + best_last + 1) * h,
                          0.5 * (best_last - best_first + 1) * h);
  plane.how = "largest cross-section from " + Mm(z_min + best_first * h) + " to " +
              Mm(z_min + (best_last + 1) * h) + ", profile symmetric about " + Mm(plane.z_s);
  return plane;
}

// The paper: from the median slab to the nearest local maximum.
Plane UphillPlane(const SlabProfile& profile, const Sections& sec) {
  const std::vector<double>& size = sec.size;
  int k = sec.median_slab;
  for (;;) {
    const double left = k > 0 ? size[k - 1] : -1.0;
    const double right = k + 1 < sec.slabs ? size[k + 1] : -1.0;
    if (std::max(left, right) <= size[k]) break;
    k = right >= left ? k + 1 : k - 1;
  }
  return Plane{profile.Centre(k), "largest cross-section uphill from the median", false};
}

Plane FindPlane(const PointList& points_V, bool with_fills, const SlabProfile& profile, const Sections& sec,
                const SymmetryConfig& config) {
  if (std::optional<Plane> prism = PrismPlane(points_V, with_fills, sec, config)) return *prism;
  if (config.plateau_search) return PlateauPlane(sec, config);
  return UphillPlane(profile, sec);
}

// The plane refused when the mirror could not match the object: too far
// above the bottom for the boundary's distance, or adding too much.
std::optional<SymmetryResult> RefuseByRange(const Sections& sec, double z_s, const SymmetryConfig& config) {
  const double z_b = sec.z_b, z_min = sec.z_min;
  const double above = z_b - z_s, below = z_s - z_min;
  if (above > below + config.range_tolerance_slabs * sec.h) {
    return NotSymmetric("the largest cross-section (z = " + Mm(z_s) + ") lies " + Mm(above) +
                            " below the missing surface but only " + Mm(below) +
                            " above the bottom: the mirrored top would not match the object "
                            "(no horizontal symmetry plane)",
                        z_s);
  }
  const double added_height = (2.0 * z_s - z_min) - z_b;
  if (added_height > config.max_added_height_fraction * (z_b - z_min)) {
    return NotSymmetric(
        "a symmetry plane at z = " + Mm(z_s) + " would add " + Mm(added_height) +
            " above the boundary, more than " +
            std::to_string(static_cast<int>(std::lround(100.0 * config.max_added_height_fraction))) +
            "% of the observed height " + Mm(z_b - z_min),
        z_s);
  }
  return std::nullopt;
}

// Outlines above the plane against their mirror images below; the
// mirror slab may shift by one slab (the plane is known to about that).
// (mismatch, z) of every check; the verdict goes by the
// (outlier_checks + 1)-th worst, so that a fused cloud's rounded bottom
// edge or a ragged slab by the claw holes does not sink a symmetric
// object, while a real asymmetry (it spans many slabs) still does.
// Returns (mismatch, z): (0, z_s) when nothing was compared.
std::pair<double, double> WorstOutlineMismatch(const SlabProfile& profile, const Sections& sec, double z_s,
                                               const SymmetryConfig& config) {
  const double h = sec.h;
  std::vector<std::pair<double, double>> mismatches;
  const double top = sec.z_b - 0.5 * h;  // the highest full slab
  for (int i = 0; i < config.outline_checks && top - z_s > h; ++i) {
    const double z_up = z_s + h + (top - z_s - h) * (i + 0.5) / config.outline_checks;
    const Polygon up = profile.HullAt(z_up, config.min_slab_points);
    if (up.empty()) continue;
    double best = std::numeric_limits<double>::infinity();
    for (int shift = -1; shift <= 1; ++shift) {
      const double z_dn = 2.0 * z_s - z_up + shift * h;
      if (z_dn - 0.5 * h < sec.z_min) continue;
      const Polygon dn = profile.HullAt(z_dn, config.min_slab_points);
      if (!dn.empty()) best = std::min(best, OutlineMismatch(up, dn));
    }
    if (std::isfinite(best)) mismatches.emplace_back(best, z_up);
  }
  std::sort(mismatches.begin(), mismatches.end(), std::greater<>());
  double worst = 0.0, worst_z = z_s;
  if (!mismatches.empty()) {
    const size_t pick = std::min(mismatches.size() - 1, static_cast<size_t>(config.outlier_checks));
    worst = mismatches[pick].first;
    worst_z = mismatches[pick].second;
  }
  return {worst, worst_z};
}

// The plane's checks (config.check_symmetry): a refusal, or nothing with
// `*outline_mismatch` set.
std::optional<SymmetryResult> CheckPlane(const SlabProfile& profile, const Sections& sec, double z_s,
                                         const SymmetryConfig& config, double* outline_mismatch) {
  if (std::optional<SymmetryResult> refused = RefuseByRange(sec, z_s, config)) return refused;
  const auto [worst, worst_z] = WorstOutlineMismatch(profile, sec, z_s, config);
  *outline_mismatch = worst;
  if (worst > config.max_outline_mismatch) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.0f%%", 100.0 * worst);
    SymmetryResult r = NotSymmetric("the outline at z = " + Mm(worst_z) +
                                        " differs from its mirror image at z = " + Mm(2.0 * z_s - worst_z) +
                                        " by " + buf + " (plane at z = " + Mm(z_s) + ")",
                                    z_s);
    r.outline_mismatch = worst;
    return r;
  }
  return std::nullopt;
}

// The missing surface's box (V), up to the mirror of the lowest point.
// With a constant section the top is the rim's whole outline, even where
// the boundary test found only part of the rim (a rounded box held
// obliquely: 74 rim points, a third of its top mirrored); the mirror
// still adds nothing beside an original point.
Eigen::AlignedBox3f MirrorBox(const SlabProfile& profile, const Sections& sec,
                              Eigen::AlignedBox3f boundary_box, const Plane& plane, float pad,
                              const SymmetryConfig& config) {
  if (plane.constant_section) {
    for (const Point2& v : profile.HullAt(sec.z_b - 0.5 * sec.h, config.min_slab_points)) {
      boundary_box.extend(
          Eigen::Vector3f(static_cast<float>(v.x()), static_cast<float>(v.y()), boundary_box.min().z()));
    }
  }
  const Eigen::Vector3f box_min(boundary_box.min().x() - pad, boundary_box.min().y() - pad,
                                boundary_box.min().z() - pad);
  const Eigen::Vector3f box_max(boundary_box.max().x() + pad, boundary_box.max().y() + pad,
                                static_cast<float>(2.0 * plane.z_s - sec.z_min) + pad);
  return Eigen::AlignedBox3f(box_min, box_max);
}

// Mirrors every point of `all` about z = z_s into `added_V` where it lands
// in the top's box or in an open hole's (padded as the top's) and has no
// original point within `gap`. Returns the points added to each open hole.
std::vector<size_t> MirrorInto(const PointList& all, const Eigen::AlignedBox3f& box,
                               const std::vector<Eigen::AlignedBox3f>* open_holes_V, float pad, double gap,
                               double z_s, PointList* added_V) {
  const Eigen::Vector3f box_min = box.min(), box_max = box.max();
  const Eigen::Vector3f g = Eigen::Vector3f::Constant(static_cast<float>(gap));
  // The original points a mirrored one could overlap, on an xy grid of
  // cell `gap` over the box (a few cell lookups instead of a KD query).
  const auto xy = [](const Eigen::Vector3f& p) { return Eigen::Vector2d(p.x(), p.y()); };
  const auto points_in = [&](const Eigen::AlignedBox3f& b) {
    geometry::GapGrid grid(xy(b.min()), xy(b.max()), gap);
    for (const Eigen::Vector3f& p : all) {
      if (b.contains(p)) grid.Add(xy(p), p);
    }
    grid.Build();
    return grid;
  };
  const geometry::GapGrid near = points_in(Eigen::AlignedBox3f(box_min - g, box_max + g));
  std::vector<Eigen::AlignedBox3f> open_boxes;  // padded as the top's box
  std::vector<geometry::GapGrid> near_open;
  if (open_holes_V != nullptr) {
    for (const Eigen::AlignedBox3f& b : *open_holes_V) {
      if (b.isEmpty()) continue;
      const Eigen::Vector3f p3 = Eigen::Vector3f::Constant(pad);
      open_boxes.emplace_back(b.min() - p3, b.max() + p3);
      near_open.push_back(
          points_in(Eigen::AlignedBox3f(open_boxes.back().min() - g, open_boxes.back().max() + g)));
    }
  }
  std::vector<size_t> in_open(open_boxes.size(), 0);
  for (const Eigen::Vector3f& p : all) {
    const Eigen::Vector3f q(p.x(), p.y(), static_cast<float>(2.0 * z_s - p.z()));
    if (box.contains(q)) {
      if (!near.AnyWithin(xy(q), q)) added_V->push_back(q);
      continue;
    }
    for (size_t k = 0; k < open_boxes.size(); ++k) {
      if (open_boxes[k].contains(q)) {
        if (!near_open[k].AnyWithin(xy(q), q)) added_V->push_back(q), ++in_open[k];
        break;
      }
    }
  }
  return in_open;
}

// The note on the open holes the image filled ("" when none).
std::string OpenHolesNote(const std::vector<size_t>& in_open) {
  const auto filled = [](size_t n) { return n > 0; };
  const size_t holes_filled = static_cast<size_t>(std::count_if(in_open.begin(), in_open.end(), filled));
  if (holes_filled == 0) return "";
  return "; the image also fills " + std::to_string(holes_filled) + " claw hole(s) no fit or line closed (" +
         std::to_string(std::accumulate(in_open.begin(), in_open.end(), size_t{0})) + " points)";
}

}  // namespace

SymmetryConfig SymmetryConfig::Paper() {
  SymmetryConfig config;
  config.plateau_search = false;
  config.check_symmetry = false;
  config.fit_sectors = 0;
  return config;
}

void SymmetryConfig::Validate() const {
  const std::string p = "SymmetryConfig.";
  Require(slab_thickness_d > 0.0 && slab_thickness_d <= 1000.0, p + "slab_thickness_d must be in (0, 1000]");
  Require(min_slab_thickness_m > 0.0 && min_slab_thickness_m < 1.0,
          p + "min_slab_thickness_m must be in (0, 1) m");
  Require(min_slab_points >= 3, p + "min_slab_points must be >= 3");
  Require(end_slack_slabs >= 0 && end_slack_slabs <= 100, p + "end_slack_slabs must be in [0, 100]");
  Require(plateau_tolerance >= 0.0 && plateau_tolerance < 1.0, p + "plateau_tolerance must be in [0, 1)");
  Require(max_outline_mismatch >= 0.0 && max_outline_mismatch <= 10.0,
          p + "max_outline_mismatch must be in [0, 10]");
  Require(outline_checks >= 1 && outline_checks <= 1000, p + "outline_checks must be in [1, 1000]");
  Require(outlier_checks >= 0 && outlier_checks < outline_checks,
          p + "outlier_checks must be in [0, outline_checks)");
  Require(prism_fraction > 0.0 && prism_fraction <= 1.0, p + "prism_fraction must be in (0, 1]");
  Require(max_added_height_fraction > 0.0 && std::isfinite(max_added_height_fraction),
          p + "max_added_height_fraction must be > 0");
  Require(range_tolerance_slabs >= 0.0 && range_tolerance_slabs <= 1000.0,
          p + "range_tolerance_slabs must be in [0, 1000]");
  Require(spacing_samples >= 10, p + "spacing_samples must be >= 10");
  Require(fit_sectors >= 0 && fit_sectors <= 360, p + "fit_sectors must be in [0, 360]");
  Require(fit_reach_cells >= 0 && fit_reach_cells <= 10, p + "fit_reach_cells must be in [0, 10]");
  Require(fit_max_offset_m >= 0.0 && fit_max_offset_m <= 0.05, p + "fit_max_offset_m must be in [0, 0.05]");
}

SymmetryResult RepairMissingSurface(const PointList& points_V, const HoleBoundary& missing_surface,
                                    const SymmetryConfig& config, const NeighborIndex* index_V,
                                    const PointList* added_before_V,
                                    const std::vector<Eigen::AlignedBox3f>* open_holes_V) {
  CheckSymmetryInputs(points_V, missing_surface, config, index_V, added_before_V);
  const double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (points_V.size() < static_cast<size_t>(3 * config.min_slab_points)) {
    return NotSymmetric("too few points (" + std::to_string(points_V.size()) + ")", kNaN);
  }
  if (missing_surface.points_V.size() < 3) {
    return NotSymmetric("missing-surface boundary has fewer than 3 points", kNaN);
  }

  std::unique_ptr<NeighborIndex> own_index;
  if (index_V == nullptr) {
    own_index = std::make_unique<NeighborIndex>(points_V);
    index_V = own_index.get();
  }
  const double d = MeanNearestDistance(*index_V, config.spacing_samples);
  if (!(d > 0.0)) return NotSymmetric("the points coincide (no spacing)", kNaN);
  // The cloud and the earlier fills, used alike from here on.
  const PointList merged = WithEarlierFills(points_V, added_before_V);
  const PointList& all = merged.empty() ? points_V : merged;
  const Heights heights = HeightsOf(missing_surface, all);

  // Cross-section profile between the bottom and the boundary.
  Sections sec;
  sec.z_min = heights.z_min;
  sec.z_b = heights.z_b;
  sec.h = std::max(config.slab_thickness_d * d, config.min_slab_thickness_m);
  sec.slabs = FloorToInt((sec.z_b - sec.z_min) / sec.h, 0, kMaxProfileSlabs + 1);
  if (sec.slabs > kMaxProfileSlabs) {
    return NotSymmetric("the cloud reaches " + Mm(sec.z_b - sec.z_min) + " below the boundary: more than " +
                            std::to_string(kMaxProfileSlabs) + " cross-sections to compare",
                        kNaN);
  }
  if (sec.slabs < 3) {
    return NotSymmetric("the boundary is only " + Mm(sec.z_b - sec.z_min) +
                            " above the lowest point: no cross-sections to compare",
                        kNaN);
  }
  const SlabProfile profile(all, sec.z_min, sec.h, sec.slabs);
  sec.median_slab = FloorToInt((heights.z_median - sec.z_min) / sec.h, 0, sec.slabs - 1);
  if (!SectionSizes(profile, sec.median_slab, config.min_slab_points, &sec.size, &sec.first_valid,
                    &sec.last_valid)) {
    return NotSymmetric("no cross-section has enough points", kNaN);
  }

  Plane plane = FindPlane(points_V, !merged.empty(), profile, sec, config);
  SymmetryResult result;
  result.symmetry_plane_z = plane.z_s;
  if (config.check_symmetry) {
    std::optional<SymmetryResult> refused =
        CheckPlane(profile, sec, plane.z_s, config, &result.outline_mismatch);
    if (refused) return std::move(*refused);
  }

  // The missing surface's box and the mirrored points that land in it.
  const float pad = static_cast<float>(kHoleBoxPadSpacings * d);
  const Eigen::AlignedBox3f box = MirrorBox(profile, sec, heights.boundary_box, plane, pad, config);
  result.box_min_V = box.min();
  result.box_max_V = box.max();
  const double gap = kNewPointGapSpacings * d;
  const std::vector<size_t> in_open =
      MirrorInto(all, box, open_holes_V, pad, gap, plane.z_s, &result.added_V);
  // A constant section's image is exact by construction; the fit would
  // only move its corners' radii by the sampling, off the walls.
  if (!plane.constant_section) {
    FitImageToObserved(points_V, all, plane.z_s, sec.h, box.max().z(), config, &result.added_V);
  }
  plane.how += OpenHolesNote(in_open);
  result.symmetric = true;
  result.constant_section = plane.constant_section;
  result.reason = plane.how;
  return result;
}

}  // namespace graspfill::repair
