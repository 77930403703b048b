// SPDX-License-Identifier: BSD-3-Clause
#include "claw_hole_repair.hpp"

#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "clamped_int.hpp"
#include "gap_test.hpp"
#include "geometry/circle_fit.hpp"
#include "graspfill/core/require.hpp"
#include "hole_fill.hpp"
#include "local_surfaces.hpp"
#include "poisson_surface.hpp"
#include "sampling_gaps.hpp"
#include "slab_profile.hpp"

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

using namespace fill;  // the fill's pieces: hole_fill, gap_test, local_surfaces, poisson_surface

namespace {

// The support points in front of the cloud's centroid along n: on a convex
// object they form one sheet over the plane (the far side of a narrow top,
// or of a small object, would fold the height field).
std::vector<int> FrontOf(const PointList& points, const std::vector<int>& support, const Eigen::Vector3d& n,
                         const Eigen::Vector3f& centroid) {
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
//  - else nothing (false): the caller falls back to the thin plate.
struct Sheets {
  HeightField a, b;
  bool two{false};
  Quadric quadric;
  bool use_quadric{false};
};

bool FitSheets(const NeighborIndex& index, const std::vector<int>& support, const PointList& rim,
               const HoleFrame& frame, const Eigen::Vector3f& centroid, const ClawRepairConfig& config,
               double d, Sheets* out) {
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
  const bool sheet_fits =
      FitHeightField(points, front, frame, config.polynomial_degree, config.irls_iterations, floor, &sheet) &&
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
    if (FitQuadric(points, probe, w, config.irls_iterations, floor, &quadric) && !quadric.IsPlanePair()) {
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
  if (static_cast<int>(group_a.size()) >= min_points && static_cast<int>(group_b.size()) >= min_points &&
      FitHeightField(points, group_a, FrameFromPlane(pts_a, centroid), config.polynomial_degree,
                     config.irls_iterations, floor, &a) &&
      FitHeightField(points, group_b, FrameFromPlane(pts_b, centroid), config.polynomial_degree,
                     config.irls_iterations, floor, &b) &&
      a.sigma_m <= config.max_fit_sigma_m && b.sigma_m <= config.max_fit_sigma_m && a.Above(c) < 0.0 &&
      b.Above(c) < 0.0) {  // convex edge only
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

// A hole whose rim's plane has a normal within 45 degrees of horizontal
// is in a wall (V's z is up).
constexpr double kMaxWallNormalZ = 0.7071;

// The convex outline of the observed points around each height (slabs of
// `slab_m`, built on first use), and their widest distance from the
// slab's centre.
// A wall's hole is filled by a surface that bounds the object from the
// side: its samples deep inside the outline at their height are not on
// that wall. A hole that opens into the missing top takes part of the
// top's rim into its boundary, and its surface, sampled over that rim's
// shadow, can cross under the top (a box's: a thin plate 3-9 mm under
// it); a sheet over a rounded box's wall can bend into it. Nor does it
// reach past the widest observed point
// (ClawRepairConfig::max_outside_widest_m).
class ObservedOutlines {
 public:
  // Over the heights min_z..max_z (points outside them are left out), in
  // at most kMaxProfileSlabs slabs.
  ObservedOutlines(const PointList& points_V, float min_z, float max_z, double slab_m)
      : profile_(points_V, min_z, slab_m, FloorToInt((max_z - min_z) / slab_m, 0, kMaxProfileSlabs - 1) + 1),
        hulls_(static_cast<size_t>(profile_.count())),
        built_(static_cast<size_t>(profile_.count()), 0),
        centres_(static_cast<size_t>(profile_.count()), Eigen::Vector2f::Zero()),
        widest_(static_cast<size_t>(profile_.count()), 0.0f),
        roundness_rms_(static_cast<size_t>(profile_.count()), 0.0f) {
    for (int k = 0; k < profile_.count(); ++k) {
      const std::vector<int>& slab = profile_.Indices(k);
      if (slab.empty()) continue;
      // The slab's centre: its circle's, unless that lies past its widest
      // point from V's axis (a flat face alone), then the axis. V's axis
      // misses a bottle's neck by 2-3 mm (tilted by the body below it).
      geometry::CircleFit fit;
      float from_axis = 0.0f;
      for (int i : slab) {
        const Eigen::Vector3f& p = points_V[static_cast<size_t>(i)];
        fit.Add(p.x(), p.y());
        from_axis = std::max(from_axis, p.head<2>().norm());
      }
      const size_t s = static_cast<size_t>(k);
      const std::optional<Eigen::Vector2d> c = fit.Centre();
      if (c && c->norm() < from_axis) centres_[s] = c->cast<float>();
      double sum_r = 0.0, sum_r2 = 0.0;
      for (int i : slab) {
        const float r = (points_V[static_cast<size_t>(i)].head<2>() - centres_[s]).norm();
        widest_[s] = std::max(widest_[s], r);
        sum_r += r;
        sum_r2 += static_cast<double>(r) * r;
      }
      const double mean = sum_r / static_cast<double>(slab.size());
      roundness_rms_[s] = static_cast<float>(
          std::sqrt(std::max(0.0, sum_r2 / static_cast<double>(slab.size()) - mean * mean)));
    }
  }
  // Deeper than `depth_m` inside the outline at p's height; false where
  // too few points give no outline.
  bool Inside(const Eigen::Vector3f& p, double depth_m) {
    const int k = profile_.SlabOf(p.z());
    if (k < 0) return false;
    if (!built_[static_cast<size_t>(k)]) {
      hulls_[static_cast<size_t>(k)] = profile_.Hull(k, kMinPoints);
      built_[static_cast<size_t>(k)] = 1;
    }
    return geometry::DepthInsideConvex(hulls_[static_cast<size_t>(k)], p.head<2>().cast<double>()) > depth_m;
  }
  // Farther than `margin_m` from its slab's centre than every point of
  // the slab, where they lie on a circle: a box's or an ellipse's widest
  // points may be the ones the claw hides (the protocol's elliptic
  // cylinder: 10% of its fills). An ellipse's distances from its centre
  // have an RMS of ~(a - b) / 2.8 and its hidden extreme lies up to a - b
  // past the widest seen point: within the margin where that RMS is under
  // margin / 2.8. False where too few points lie there.
  bool BeyondWidest(const Eigen::Vector3f& p, double margin_m) const {
    const int k = profile_.SlabOf(p.z());
    if (k < 0 || static_cast<int>(profile_.Indices(k).size()) < kMinPoints) return false;
    const size_t s = static_cast<size_t>(k);
    return roundness_rms_[s] <= margin_m / (2.0 * M_SQRT2) &&
           (p.head<2>() - centres_[s]).norm() > widest_[s] + margin_m;
  }

 private:
  static constexpr int kMinPoints = 20;
  SlabProfile profile_;
  std::vector<std::vector<Eigen::Vector2d>> hulls_;
  std::vector<char> built_;
  std::vector<Eigen::Vector2f> centres_;
  std::vector<float> widest_;         // from the centre [m]
  std::vector<float> roundness_rms_;  // of the distances from the centre [m]
};

// The claw holes to fill (kClaw, a rim of 3 points or more) and their
// indices into `claw_holes`.
void SelectClawHoles(const std::vector<HoleBoundary>& claw_holes, std::vector<const HoleBoundary*>* holes,
                     std::vector<size_t>* hole_index) {
  for (size_t k = 0; k < claw_holes.size(); ++k) {
    const HoleBoundary& hole = claw_holes[k];
    if (hole.kind == HoleKind::kClaw && hole.points_V.size() >= 3) {
      CheckFinite(hole.points_V, "RepairClawHoles: claw-hole boundary");
      holes->push_back(&hole);
      hole_index->push_back(k);
    }
  }
}

// What every hole's fill reads of the cloud, found once.
struct CloudFacts {
  const PointList& points_V;
  const std::vector<Eigen::Vector3f>* normals_V;  // may be null
  const NeighborIndex& index;
  const ClawRepairConfig& config;
  Eigen::Vector3f centroid;
  float min_z{0.0f}, max_z{0.0f}, mid_z{0.0f};
  double cos_max{0.0};
  // Stray points far from the object can end up on a rim: a fill's samples
  // must stay by the cloud's bulk, within its size of it (found by
  // fuzz_repair: a fill point ~1e33 m away).
  Box by_object{};
};

CloudFacts FactsOf(const PointList& points_V, const std::vector<Eigen::Vector3f>* normals_V,
                   const NeighborIndex& index, const ClawRepairConfig& config) {
  CloudFacts cloud{points_V, normals_V, index, config, Centroid(points_V)};
  float max_z = -std::numeric_limits<float>::infinity();
  float min_z = std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : points_V) max_z = std::max(max_z, p.z()), min_z = std::min(min_z, p.z());
  cloud.min_z = min_z;
  cloud.max_z = max_z;
  cloud.mid_z = 0.5f * (min_z + max_z);
  cloud.cos_max = std::cos(config.max_normal_deviation_deg * M_PI / 180.0);
  const Box robust = RobustBox(points_V);
  cloud.by_object = Box(robust.min() - robust.sizes(), robust.max() + robust.sizes());
  return cloud;
}

// What the holes share, filled one after the other.
struct FillsSoFar {
  std::unique_ptr<AddedPoints> earlier;  // the fills of the holes before
  // The paper's single surface of all the side points, built on first use.
  std::unique_ptr<PoissonSurface> global_surface;
  std::optional<ObservedOutlines> outlines;  // built for the first hole tested
};

// Normals of a subset: the caller's, else estimated on demand.
std::vector<Eigen::Vector3f> NormalsOf(const CloudFacts& cloud, const std::vector<int>& subset) {
  if (cloud.normals_V == nullptr) {
    return EstimateNormals(cloud.index, subset, cloud.config.normal_knn, cloud.centroid);
  }
  std::vector<Eigen::Vector3f> n(subset.size());
  for (size_t i = 0; i < subset.size(); ++i) n[i] = (*cloud.normals_V)[subset[i]];
  return n;
}

// One hole as its fill sees it.
struct HoleGeometry {
  const PointList& rim;
  Box box{};                   // the rim's
  Box support_box{};           // the rim's, grown by local_margin_m
  std::vector<int> support{};  // the cloud's points in support_box
  HoleFrame frame{};
  double d{0.0};        // the support's mean spacing [m]
  double density{0.0};  // of the fill [1/m^2]
  double pad{0.0};      // [m]
  FillRegion region{};  // the rim's shadow
  double bulge_m{0.0};
};

void FindSupport(const CloudFacts& cloud, HoleGeometry* hole) {
  hole->box.setEmpty();
  for (const Eigen::Vector3f& p : hole->rim) hole->box.extend(p);
  const float margin = static_cast<float>(cloud.config.local_margin_m);
  hole->support_box = Box(hole->box.min() - Eigen::Vector3f::Constant(margin),
                          hole->box.max() + Eigen::Vector3f::Constant(margin));
  for (size_t i = 0; i < cloud.points_V.size(); ++i) {
    if (hole->support_box.contains(cloud.points_V[i])) hole->support.push_back(static_cast<int>(i));
  }
}

// The hole's frame, outward: the caller's normals when given, else away
// from the centroid.
HoleFrame OutwardFrame(const CloudFacts& cloud, const HoleGeometry& hole) {
  Eigen::Vector3d outward = Eigen::Vector3d::Zero();
  if (cloud.normals_V != nullptr) {
    for (int i : hole.support) outward += (*cloud.normals_V)[i].cast<double>();
  }
  if (outward.norm() < 1e-9) outward = (hole.box.center() - cloud.centroid).cast<double>();
  return MakeHoleFrame(hole.rim, cloud.points_V, hole.support, outward);
}

// The grid spans the support box's shadow, so that the samples of a
// second sheet (an edge hole), too, are tested on it.
void BuildGapGrid(const HoleGeometry& hole, const PointList& out, GapTest* gap) {
  Eigen::Vector2d grid_lo = hole.region.lo.head<2>(), grid_hi = hole.region.hi.head<2>();
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d l =
        hole.frame.Local(hole.support_box.corner(static_cast<Box::CornerType>(c)).cast<double>());
    grid_lo = grid_lo.cwiseMin(l.head<2>());
    grid_hi = grid_hi.cwiseMax(l.head<2>());
  }
  gap->BuildGrid(hole.frame, grid_lo, grid_hi, hole.support, hole.support_box, out);
}

// The explicit local surfaces (kLocalFit): one or two sheets, else the
// thin plate; false when neither explains the points around the hole.
bool SampleLocalFit(const CloudFacts& cloud, const HoleGeometry& hole, Rng* rng, GapTest* gap,
                    PointList* fill) {
  const double d = hole.d;
  // A sheet parametrizes a quadric's samples: it is within ~1 mm of it.
  const double max_snap = std::max(0.003, 10.0 * d);
  Sheets sheets;
  // Otherwise the points around the hole are not one or two smooth
  // sheets: the hole falls back to the thin plate below.
  if (FitSheets(cloud.index, hole.support, hole.rim, hole.frame, cloud.centroid, cloud.config, d, &sheets)) {
    const double clip_tol = 0.5 * d;
    // Each sheet over the rim's shadow in its own frame.
    const auto region_of = [&](const HoleFrame& f) {
      return RimRegion(hole.rim, f, hole.pad, hole.region.z_lo, hole.region.z_hi);
    };
    SampleHeightField(sheets.a, region_of(sheets.a.frame), hole.density, sheets.two ? &sheets.b : nullptr,
                      clip_tol, sheets.use_quadric ? &sheets.quadric : nullptr, max_snap, rng, gap, fill);
    if (sheets.two) {
      SampleHeightField(sheets.b, region_of(sheets.b.frame), hole.density, &sheets.a, clip_tol, nullptr, 0.0,
                        rng, gap, fill);
    }
    return true;
  }
  ThinPlateSheet smooth;
  if (FitThinPlate(cloud.index, hole.support, hole.frame, cloud.centroid, d, kThinPlateCentres, &smooth)) {
    smooth.w_pad = 2.0 * d + hole.bulge_m;  // past the support's heights: the bulge
    SampleHeightField(smooth, hole.region, hole.density, nullptr, 0.0,
                      smooth.use_quadric ? &smooth.quadric : nullptr, max_snap, rng, gap, fill);
    return true;
  }
  return false;
}

// The paper's surface: one Poisson surface of all the side points (~0.3-1
// s), made for the first hole and shared by the rest.
void SamplePoisson(const CloudFacts& cloud, const HoleGeometry& hole, FillsSoFar* so_far, Rng* rng,
                   GapTest* gap, PointList* fill) {
  const ClawRepairConfig& config = cloud.config;
  if (!so_far->global_surface) {
    std::vector<int> side(cloud.points_V.size());  // the paper's side points: all of them
    std::iota(side.begin(), side.end(), 0);
    so_far->global_surface = std::make_unique<PoissonSurface>(ReconstructPoisson(
        cloud.points_V, side, NormalsOf(cloud, side), config.poisson_depth, config.poisson_scale));
  }
  const PoissonSurface* surface = so_far->global_surface.get();
  // Along n: the rim's spread, the surface's sag or bulge over the hole
  // (up to about a cell, and the bulge), and the pad.
  const double n_pad = hole.pad + config.poisson_box_pad_cells * surface->cell_m + hole.bulge_m;
  FillRegion region = hole.region;
  region.lo.z() -= n_pad;
  region.hi.z() += n_pad;
  SampleMesh(*surface->mesh, hole.frame, region, true, cloud.cos_max, nullptr, hole.density, rng, gap, fill);
}

// Keeps the fill's samples by the object and, where tested, within the
// observed outlines; adds them to `out` and to the earlier fills.
void KeepFillsByTheOutlines(const CloudFacts& cloud, const HoleGeometry& hole, const PointList& fill,
                            FillsSoFar* so_far, PointList* out) {
  const ClawRepairConfig& config = cloud.config;
  // A wall's samples, and those of any hole reaching the upper half (a
  // round body's shoulder under the missing top); a horizontal face
  // lower down (a bottom) lies inside its own outline.
  const bool tested = (config.max_inside_outline_m > 0.0 || config.max_outside_widest_m > 0.0) &&
                      (std::abs(hole.frame.n.z()) < kMaxWallNormalZ || hole.box.max().z() > cloud.mid_z);
  std::optional<ObservedOutlines>& outlines = so_far->outlines;
  if (tested && !outlines) {
    // Slabs of 2 D: a point lies within D of its slab's middle, so a
    // wall leaning up to ~70 degrees stays within 3 mm of its outline.
    const double slab_m = std::max(2.0 * MeanNearestDistance(cloud.index, 256), 0.001);
    // Over the cloud's heights; where a stray far above or below makes
    // them more than kMaxProfileSlabs slabs (2.4e35, found by
    // fuzz_repair), over those a fill point can have (by_object's).
    float lo_z = cloud.min_z, hi_z = cloud.max_z;
    if (!((hi_z - lo_z) / slab_m < kMaxProfileSlabs)) {
      lo_z = std::max(lo_z, cloud.by_object.min().z());
      hi_z = std::min(hi_z, cloud.by_object.max().z());
    }
    outlines.emplace(cloud.points_V, lo_z, hi_z, slab_m);
  }
  for (const Eigen::Vector3f& p : fill) {
    if (!cloud.by_object.contains(p)) continue;
    if (tested && config.max_inside_outline_m > 0.0 && outlines->Inside(p, config.max_inside_outline_m))
      continue;
    if (tested && config.max_outside_widest_m > 0.0 &&
        outlines->BeyondWidest(p, config.max_outside_widest_m)) {
      continue;
    }
    so_far->earlier->Add(p);
    out->push_back(p);
  }
}

enum class HoleFill {
  kSkipped,   // too few support points, or no spacing: neither filled nor reported
  kLeftOpen,  // reported in holes_left_open
  kFilled,
};

// Fills hole `h` (its samples seeded by h) beside the fills so far.
HoleFill FillHole(const CloudFacts& cloud, const PointList& rim, size_t h, FillsSoFar* so_far,
                  PointList* out) {
  const ClawRepairConfig& config = cloud.config;
  HoleGeometry hole{rim};
  FindSupport(cloud, &hole);
  if (static_cast<int>(hole.support.size()) < config.min_support_points) return HoleFill::kSkipped;
  if (static_cast<double>(hole.support.size()) >
      config.max_support_share * static_cast<double>(cloud.points_V.size())) {
    return HoleFill::kLeftOpen;
  }
  const Spacing spacing = EstimateSpacing(cloud.index, hole.support, 200);
  if (spacing.mean_nn_m <= 0.0 || spacing.density_per_m2 <= 0.0) return HoleFill::kSkipped;
  hole.d = spacing.mean_nn_m;
  hole.density = spacing.density_per_m2 * config.fill_density_factor;
  const double gap_m = kNewPointGapSpacings * hole.d;
  if (!so_far->earlier) so_far->earlier = std::make_unique<AddedPoints>(std::max(gap_m, 1e-4));
  Rng rng(MixSeed(config.seed, h));

  hole.frame = OutwardFrame(cloud, hole);
  hole.pad = kHoleBoxPadSpacings * hole.d;
  hole.region =
      RimRegion(rim, hole.frame, hole.pad, hole.box.min().z() - hole.pad, hole.box.max().z() + hole.pad);
  GapTest gap(cloud.index, so_far->earlier.get(), gap_m);
  BuildGapGrid(hole, *out, &gap);

  PointList fill;
  // A surface sampled over the hole may bulge out of the rim's plane by
  // the curvature's a^2 / 2r, bounded by a quarter of the hole's width.
  hole.bulge_m = 0.25 * (hole.region.hi.head<2>() - hole.region.lo.head<2>()).minCoeff();
  if (config.surface == ClawSurface::kLocalFit) {
    if (!SampleLocalFit(cloud, hole, &rng, &gap, &fill)) return HoleFill::kLeftOpen;
  } else {
    SamplePoisson(cloud, hole, so_far, &rng, &gap, &fill);
  }
  KeepFillsByTheOutlines(cloud, hole, fill, so_far, out);
  return HoleFill::kFilled;
}

}  // namespace

ClawRepairConfig ClawRepairConfig::Paper() {
  ClawRepairConfig config;
  config.surface = ClawSurface::kPoisson;
  config.max_support_share = 1.0;  // no such rule in the paper
  config.max_inside_outline_m = 0.0;
  config.max_outside_widest_m = 0.0;
  config.max_inside_top_rim_m = 0.0;
  return config;
}

void ClawRepairConfig::Validate() const {
  const std::string p = "ClawRepairConfig.";
  Require(local_margin_m > 0.0 && std::isfinite(local_margin_m), p + "local_margin_m must be > 0");
  Require(min_support_points >= 3, p + "min_support_points must be >= 3");
  Require(max_inside_outline_m >= 0.0 && std::isfinite(max_inside_outline_m),
          p + "max_inside_outline_m must be >= 0");
  Require(max_outside_widest_m >= 0.0 && std::isfinite(max_outside_widest_m),
          p + "max_outside_widest_m must be >= 0");
  Require(max_inside_top_rim_m >= 0.0 && std::isfinite(max_inside_top_rim_m),
          p + "max_inside_top_rim_m must be >= 0");
  Require(max_support_share > 0.0 && max_support_share <= 1.0, p + "max_support_share must be in (0, 1]");
  Require(polynomial_degree >= 1 && polynomial_degree <= 5, p + "polynomial_degree must be in [1, 5]");
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
}

size_t DropFillsOnTheTop(const PointList& rim_V, double max_inside_m, PointList* fills_V) {
  if (rim_V.size() < 3 || !(max_inside_m > 0.0)) return 0;
  std::vector<Eigen::Vector2d> xy;
  for (const Eigen::Vector3f& p : rim_V) xy.push_back(p.head<2>().cast<double>());
  const std::vector<Eigen::Vector2d> outline = geometry::ConvexHull2d(&xy);
  // The rim's highest point per 5 degrees around V's axis; a fill is
  // compared with the highest within 15 degrees of it (a ragged rim).
  constexpr int kBins = 72, kReach = 3;
  const auto bin_of = [](const Eigen::Vector3f& p) {
    const double a = std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x())) + M_PI;
    return std::clamp(static_cast<int>(a / (2.0 * M_PI) * kBins), 0, kBins - 1);
  };
  std::vector<float> top(kBins, -std::numeric_limits<float>::infinity());
  for (const Eigen::Vector3f& p : rim_V) top[bin_of(p)] = std::max(top[bin_of(p)], p.z());
  const size_t before = fills_V->size();
  const auto on_top = [&](const Eigen::Vector3f& p) {
    const int b = bin_of(p);
    float rim_z = -std::numeric_limits<float>::infinity();
    for (int k = -kReach; k <= kReach; ++k) rim_z = std::max(rim_z, top[(b + k + kBins) % kBins]);
    return std::isfinite(rim_z) && p.z() > rim_z &&
           geometry::DepthInsideConvex(outline, p.head<2>().cast<double>()) > max_inside_m;
  };
  fills_V->erase(std::remove_if(fills_V->begin(), fills_V->end(), on_top), fills_V->end());
  return before - fills_V->size();
}

PointList RepairClawHoles(const PointList& points_V, const std::vector<HoleBoundary>& claw_holes,
                          const ClawRepairConfig& config, const std::vector<Eigen::Vector3f>* normals_V,
                          const NeighborIndex* index_V, std::vector<size_t>* holes_left_open) {
  config.Validate();
  CheckInputs(points_V, normals_V, index_V, "RepairClawHoles");
  if (holes_left_open != nullptr) holes_left_open->clear();
  PointList out;
  if (points_V.empty()) return out;
  std::vector<const HoleBoundary*> holes;
  std::vector<size_t> hole_index;  // into claw_holes
  SelectClawHoles(claw_holes, &holes, &hole_index);
  if (holes.empty()) return out;

  std::unique_ptr<NeighborIndex> own_index;
  if (index_V == nullptr) {
    own_index = std::make_unique<NeighborIndex>(points_V);
    index_V = own_index.get();
  }
  const CloudFacts cloud = FactsOf(points_V, normals_V, *index_V, config);
  FillsSoFar so_far;
  for (size_t h = 0; h < holes.size(); ++h) {
    const HoleFill fill = FillHole(cloud, holes[h]->points_V, h, &so_far, &out);
    if (fill == HoleFill::kLeftOpen && holes_left_open != nullptr) holes_left_open->push_back(hole_index[h]);
  }
  return out;
}

}  // namespace graspfill::repair
