// SPDX-License-Identifier: BSD-3-Clause
#include "evidence_top.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "clamped_int.hpp"
#include "geometry/polygon_2d.hpp"
#include "local_surfaces.hpp"

namespace graspfill::repair {
namespace {

using Ring = std::vector<Eigen::Vector2d>;

// Points along the closed polygon `hull`, about `spacing` apart.
Ring SampleOutline(const Ring& hull, double spacing) {
  Ring ring;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d a = hull[i], b = hull[(i + 1) % hull.size()];
    const int n = CeilToInt((b - a).norm() / spacing, 1, std::numeric_limits<int>::max());
    for (int s = 0; s < n; ++s) ring.push_back(a + (b - a) * (static_cast<double>(s) / n));
  }
  return ring;
}

// The RMS distance in x-y from the outline of each band `band_m` thick,
// from `z_top` down to the lowest point, to the convex `top_hull`: 0 for a
// prism's walls, the taper for a cup's. Infinity when no band has an
// outline.
double ExtrusionMisfit(const PointList& points_V, const Ring& top_hull, float z_top, double band_m,
                       double spacing_m) {
  float low = z_top;
  for (const Eigen::Vector3f& p : points_V) low = std::min(low, p.z());
  const int bands = CeilToInt((z_top - low) / band_m, 1, 1000);
  std::vector<Ring> slices(static_cast<size_t>(bands));
  for (const Eigen::Vector3f& p : points_V) {
    const int b = std::min(bands - 1, static_cast<int>((z_top - p.z()) / band_m));
    slices[static_cast<size_t>(b)].emplace_back(p.x(), p.y());
  }
  double sum_sq = 0.0;
  size_t n = 0;
  for (Ring& slice : slices) {
    const Ring hull = geometry::ConvexHull2d(&slice);
    if (hull.size() < 3) continue;
    for (const Eigen::Vector2d& q : SampleOutline(hull, spacing_m)) {
      const double d = geometry::DepthInsideConvex(top_hull, q);
      sum_sq += d * d;
      ++n;
    }
  }
  return n ? std::sqrt(sum_sq / static_cast<double>(n)) : std::numeric_limits<double>::infinity();
}

Eigen::Vector3f At(const Eigen::Vector2d& xy, double z) {
  return Eigen::Vector3f(static_cast<float>(xy.x()), static_cast<float>(xy.y()), static_cast<float>(z));
}

// Keeps the candidates with no point of `observed` or `fills` (may be
// null) within 0.75 spacing and not seen free (counted in *rejected_free).
PointList KeepNewAndUnseen(const PointList& candidates, const NeighborIndex& observed,
                           const NeighborIndex* fills, double spacing_m,
                           const evidence::VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                           int* rejected_free) {
  PointList kept;
  size_t first_key_frame = 0;  // neighbouring candidates are mostly carved by the same key frame
  for (const Eigen::Vector3f& c : candidates) {
    if (observed.AnyWithin(c, 0.75 * spacing_m)) continue;
    if (fills && fills->AnyWithin(c, 0.75 * spacing_m)) continue;
    if (record.SeenFree(T_in_V * c, 0.0f, false, &first_key_frame)) {
      ++*rejected_free;
      continue;
    }
    kept.push_back(c);
  }
  return kept;
}

// The dome over a tapered top (fruit, a ball): z = f(x, y), quadratic,
// fitted to the observed points within config.dome_support_m of the top `z_wall`,
// sampled on a grid inside the outline of those points, where none of them
// lies within a spacing in x-y (the cap they leave open). Empty unless f
// curves down on every side with its apex inside that outline, where it
// may rise no more than the config's search reach above the wall. (Not the
// top band's outline: where the highest points seen lie to one side of a
// round top, the apex lies outside it, and the top's middle stayed open.)
// With `first_only`, the first candidate alone: whether there is a dome.
// `surface`: the surface they lie on.
PointList DomeCandidates(const PointList& points_V, float z_wall, double spacing_m,
                         const EvidenceConfig& config, bool first_only, DomeSurface* surface) {
  std::vector<int> support;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Ring outline;
  PointList columns;  // the support flattened onto z = 0
  for (size_t i = 0; i < points_V.size(); ++i) {
    const Eigen::Vector3f& p = points_V[i];
    if (p.z() < z_wall - config.dome_support_m) continue;
    support.push_back(static_cast<int>(i));
    centre += p.cast<double>();
    outline.emplace_back(p.x(), p.y());
    columns.emplace_back(p.x(), p.y(), 0.0f);
  }
  outline = geometry::ConvexHull2d(&outline);
  if (outline.size() < 3) return {};
  fill::HoleFrame frame;  // V's axes about the band's centre
  frame.origin = centre / static_cast<double>(support.size());
  fill::HeightField f;
  // A floor of a few cm on the robust scale: a plain least-squares fit (the
  // band's heights spread by the dome itself, not by outliers).
  constexpr int kDegree = 2, kIterations = 3;
  constexpr double kSigmaFloorM = 0.05;
  if (!fill::FitHeightField(points_V, support, frame, kDegree, kIterations, kSigmaFloorM, &f)) return {};
  // A round top's band is a paraboloid to ~1 mm (the zoo's fruit and balls:
  // 0.7-1.0 mm RMS); a band whose walls stand upright under the top is
  // none (a bowl's rim: 2.4-2.7 mm; a rounded box's flat top: 2.2-2.4 mm).
  constexpr double kMaxDomeRmsM = 0.0015;
  double squares = 0.0;
  for (int i : support) squares += std::pow(f.Above(points_V[static_cast<size_t>(i)].cast<double>()), 2);
  if (!(squares <= kMaxDomeRmsM * kMaxDomeRmsM * static_cast<double>(support.size()))) return {};
  // f = c0 + c1 u + c2 v + c3 u^2 + c4 uv + c5 v^2 (in u / scale, v / scale).
  const Eigen::VectorXd& c = f.coeffs;
  Eigen::Matrix2d hessian;
  hessian << 2.0 * c(3), c(4), c(4), 2.0 * c(5);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> curvature(hessian);
  if (!(curvature.eigenvalues().maxCoeff() < 0.0)) return {};  // no dome
  const Eigen::Vector2d apex_scaled = hessian.ldlt().solve(-Eigen::Vector2d(c(1), c(2)));
  const Eigen::Vector2d apex = frame.origin.head<2>() + f.scale * apex_scaled;
  if (!geometry::InsideConvex(outline, apex)) return {};
  if (f.Point(f.scale * apex_scaled.x(), f.scale * apex_scaled.y()).z() > z_wall + config.top_search_m) {
    return {};
  }
  // Over a wide cap of a ball the paraboloid sags by mm: its samples move
  // onto a quadric of the same points when one explains them (a sphere,
  // an ellipsoid), as the claw holes' fills do.
  fill::Quadric quadric;
  constexpr double kQuadricFitM = 0.0005, kMaxMoveM = 0.006;
  const bool on_quadric =
      fill::FitQuadric(points_V, support, std::vector<double>(support.size(), 1.0), 6, 0.0001, &quadric) &&
      !quadric.IsPlanePair() && quadric.sigma_m <= kQuadricFitM;
  surface->field = f;
  if (on_quadric) surface->quadric = quadric;
  const NeighborIndex seen(columns);
  PointList candidates;
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector2d& h : outline) box.extend(h);
  for (double x = box.min().x() + 0.5 * spacing_m; x < box.max().x(); x += spacing_m) {
    for (double y = box.min().y() + 0.5 * spacing_m; y < box.max().y(); y += spacing_m) {
      if (!geometry::InsideConvex(outline, {x, y})) continue;
      Eigen::Vector3d p = f.Point(x - frame.origin.x(), y - frame.origin.y());
      if (on_quadric && !quadric.Project(&p, kMaxMoveM)) continue;
      if (seen.AnyWithin(At(p.head<2>(), 0.0), spacing_m)) continue;
      candidates.push_back(p.cast<float>());
      if (first_only) return candidates;
    }
  }
  return candidates;
}

// The top's height from the rings on the outline `ring` above the highest
// observed point `z_wall`: sets top->outcome and top->top_z_V.
void FindTopHeight(const Ring& ring, float z_wall, const evidence::VisibilityRecord& record,
                   const Eigen::Isometry3f& T_in_V, const EvidenceConfig& config, EvidenceTop* top) {
  // The free share of the outline at height z: ~constant along the
  // observed wall (where the hull cuts across concave parts), jumping up
  // once the rings pass the top and the grazing rays carve them.
  const auto free_share = [&](double z) {
    int n = 0;
    size_t first_key_frame = 0;  // neighbours along the ring are mostly carved by the same key frame
    for (const Eigen::Vector2d& r : ring)
      n += record.SeenFree(T_in_V * At(r, z), 0.0f, false, &first_key_frame);
    return static_cast<double>(n) / static_cast<double>(ring.size());
  };
  // The baseline comes from well below the highest point and the search
  // starts below it too: the TSDF's truncation band behind the wall spills
  // up to ~3 mm over a top edge that rays pass over (sdf_trunc * sin of
  // the view's elevation), leaving a phantom layer above the true top.
  const double step = config.top_step_m;
  const double below = config.phantom_m;
  double base = 0.0;
  int rings = 0;
  for (double z = z_wall - below - config.top_band_m; z <= z_wall - below + 1e-9; z += step, ++rings) {
    base += free_share(z);
  }
  base /= std::max(1, rings);
  // The jump counts over the baseline and over the ring a window lower:
  // where the hull runs a little outside the wall (a few points beside a
  // finger widen it), rays carve a share of it that rises slowly towards
  // the top, and the baseline alone is passed millimetres under it.
  const int window = std::max(1, static_cast<int>(std::lround(config.top_jump_window_m / step)));
  const double first = z_wall - below + step;
  std::vector<double> shares;  // shares[i]: at first + (i - window) * step
  for (int i = 0; i < window; ++i) shares.push_back(free_share(first + (i - window) * step));
  top->outcome = TopEvidence::kNotObservable;
  for (double z = first; z <= z_wall + config.top_search_m + 1e-9; z += step) {
    const double share = free_share(z);
    const double lower = shares[shares.size() - window];
    shares.push_back(share);
    if (share >= std::max(base, lower) + config.top_free_jump) {
      top->outcome = TopEvidence::kHeightFound;
      top->top_z_V = static_cast<float>(z - step);  // the highest ring not carved
      break;
    }
  }
}

}  // namespace

Eigen::Vector3f DomeSurface::Normal(const Eigen::Vector3f& p_V) const {
  const Eigen::Vector3d p = p_V.cast<double>();
  const Eigen::Vector3d local = field.frame.Local(p);
  const Eigen::Vector3d up = field.Normal(local.x(), local.y());
  if (!quadric) return up.cast<float>();
  const Eigen::Vector3d g = quadric->Gradient(p);
  if (!(g.norm() > 0.0)) return up.cast<float>();
  // The quadric's gradient, on the field's side (out of the top).
  return (g.dot(up) < 0.0 ? -g : g).normalized().cast<float>();
}

std::string TopEvidenceName(TopEvidence outcome) {
  switch (outcome) {
    case TopEvidence::kHeightFound:
      return "height found";
    case TopEvidence::kNotObservable:
      return "not observable";
    case TopEvidence::kNoOutline:
      return "no outline";
    case TopEvidence::kTapered:
      return "tapered top";
    case TopEvidence::kDome:
      return "dome";
  }
  return "no outline";
}

EvidenceTop CloseTopFromEvidence(const NeighborIndex& observed_V, const PointList& fills_V,
                                 const evidence::VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                                 double spacing_m, const EvidenceConfig& config, bool dome_outcome_only) {
  config.Validate();
  const PointList& points_V = observed_V.points();
  EvidenceTop top;
  if (points_V.empty() || !(spacing_m > 0.0)) return top;
  float z_wall = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& p : points_V) z_wall = std::max(z_wall, p.z());
  top.wall_top_z_V = top.top_z_V = z_wall;
  Ring band;
  for (const Eigen::Vector3f& p : points_V) {
    if (p.z() >= z_wall - config.top_band_m) band.emplace_back(p.x(), p.y());
  }
  const Ring hull = geometry::ConvexHull2d(&band);
  if (hull.size() < 3) return top;
  Ring lower_band;
  const double lower_top = z_wall - config.taper_drop_m;
  for (const Eigen::Vector3f& p : points_V) {
    if (p.z() <= lower_top && p.z() >= lower_top - config.top_band_m) lower_band.emplace_back(p.x(), p.y());
  }
  const Ring lower = geometry::ConvexHull2d(&lower_band);
  // The candidates kept, with the fills' own index (the cloud's is the
  // caller's), built where some are to test: once on any path.
  const auto keep_new_and_unseen = [&](const PointList& candidates) {
    std::optional<NeighborIndex> fills;
    if (!fills_V.empty()) fills.emplace(fills_V);
    return KeepNewAndUnseen(candidates, observed_V, fills ? &*fills : nullptr, spacing_m, record, T_in_V,
                            &top.rejected_free);
  };
  if (lower.size() >= 3 &&
      geometry::PolygonArea(hull) < config.min_flat_area_ratio * geometry::PolygonArea(lower)) {
    top.outcome = TopEvidence::kTapered;
    if (config.dome_support_m > 0.0) {
      DomeSurface surface;
      const PointList dome = DomeCandidates(points_V, z_wall, spacing_m, config, dome_outcome_only, &surface);
      if (!dome.empty()) {
        top.outcome = TopEvidence::kDome;
        top.dome = std::move(surface);
        if (!dome_outcome_only) top.added_V = keep_new_and_unseen(dome);
      }
    }
    return top;
  }
  const Ring ring = SampleOutline(hull, spacing_m);
  top.extrusion_rms_m = ExtrusionMisfit(points_V, hull, z_wall, config.top_band_m, spacing_m);
  top.outline_vertices = geometry::SimplifiedVertexCount(hull, spacing_m);
  FindTopHeight(ring, z_wall, record, T_in_V, config, &top);

  // Candidates: the outline from the wall's top up to the top, then the cap.
  PointList candidates;
  for (double z = z_wall + spacing_m; z < top.top_z_V - 0.5 * spacing_m; z += spacing_m) {
    for (const Eigen::Vector2d& r : ring) candidates.push_back(At(r, z));
  }
  for (const Eigen::Vector2d& r : ring) candidates.push_back(At(r, top.top_z_V));
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector2d& h : hull) box.extend(h);
  for (double x = box.min().x() + 0.5 * spacing_m; x < box.max().x(); x += spacing_m) {
    for (double y = box.min().y() + 0.5 * spacing_m; y < box.max().y(); y += spacing_m) {
      if (geometry::InsideConvex(hull, {x, y})) candidates.push_back(At({x, y}, top.top_z_V));
    }
  }
  top.added_V = keep_new_and_unseen(candidates);
  return top;
}

}  // namespace graspfill::repair
