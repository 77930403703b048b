// SPDX-License-Identifier: BSD-3-Clause
// Test-only inputs for the repair tests: planes with round holes, and the
// paper protocol's known hole geometry, from which the virtual frame,
// classification and completion tests build their boundaries (so that those
// steps are tested without steps 2-3, boundary detection and linking).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "graspfill/core/random.hpp"
#include "graspfill/repair/repair_types.hpp"
#include "synth/paper_protocol.hpp"

namespace graspfill::repair::testing {

struct Disc {
  Eigen::Vector2f centre;
  float radius_m;
};

/// Uniform random sample of the square [-half, half]^2 at z = 0 with `n`
/// points before the discs are cut out of it.
inline PointList PlaneWithHoles(int n, float half_m, const std::vector<Disc>& holes, uint64_t seed) {
  Rng rng(seed);
  PointList points;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2f xy(static_cast<float>((2 * rng.Uniform() - 1) * half_m),
                             static_cast<float>((2 * rng.Uniform() - 1) * half_m));
    bool in_hole = false;
    for (const Disc& d : holes) in_hole = in_hole || (xy - d.centre).norm() < d.radius_m;
    if (!in_hole) points.emplace_back(xy.x(), xy.y(), 0.0f);
  }
  return points;
}

/// The protocol's holes in the object frame O, mirroring the rules of
/// src/synth/paper_protocol.cpp (top cut, finger patches).
struct ProtocolHoles {
  double top_z{0};
  bool top_grasp{true};
  double tilt{0};
  double z_centre{0};
  double half_width{0};
  double half_height{0};
  std::vector<Eigen::Vector2d> dirs;  ///< unit, radial, one per hole
};

inline ProtocolHoles HolesOf(const synth::PaperProtocolConfig& config, const Eigen::Vector3d& size) {
  ProtocolHoles h;
  h.top_z = synth::TopCutZ(config, size.z());
  h.top_grasp = config.grasp != synth::GraspWay::kMiddleStraight;
  h.z_centre = h.top_grasp ? h.top_z - 0.5 * config.claw_hole_height_m + 0.004 : 0.5 * size.z();
  h.tilt = config.grasp == synth::GraspWay::kTopOblique ? config.oblique_tilt_rad : 0.0;
  h.half_width = 0.5 * config.claw_hole_width_m;
  h.half_height = 0.5 * config.claw_hole_height_m;
  for (int i = 0; i < config.num_claw_holes; ++i) {
    const double angle = 2.0 * M_PI * i / config.num_claw_holes;
    h.dirs.emplace_back(std::cos(angle), std::sin(angle));
  }
  return h;
}

/// Finger-patch coordinates of p_O for hole i: a across the finger, b along
/// it (from the patch centre), and whether p is on the finger's side.
struct PatchCoords {
  double a{0}, b{0};
  bool front{false};
};

inline PatchCoords InPatch(const ProtocolHoles& h, size_t i, const Eigen::Vector3f& p) {
  const Eigen::Vector2d xy(p.x(), p.y());
  const Eigen::Vector2d& dir = h.dirs[i];
  const double t = dir.x() * xy.y() - dir.y() * xy.x();
  const double z = p.z() - h.z_centre;
  PatchCoords c;
  c.a = std::cos(h.tilt) * t - std::sin(h.tilt) * z;
  c.b = std::sin(h.tilt) * t + std::cos(h.tilt) * z;
  c.front = xy.dot(dir) > 0.0;
  return c;
}

/// Whether p_O lies on hole i's finger patch grown by `grow` [m] all round.
inline bool WithinPatch(const ProtocolHoles& h, size_t i, const Eigen::Vector3f& p, double grow) {
  const PatchCoords c = InPatch(h, i, p);
  return c.front && std::abs(c.a) <= h.half_width + grow && std::abs(c.b) <= h.half_height + grow;
}

/// Distance from (t, z) to the rectangle [-hw, hw] x [z0, z1] (0 inside).
inline double RectDistance(double t, double z, double hw, double z0, double z1) {
  const double dt = std::max(std::abs(t) - hw, 0.0);
  const double dz = std::max({z0 - z, z - z1, 0.0});
  return std::hypot(dt, dz);
}

/// Distance of p_O to the nearest rim of a straight grasp's holes (the tilt
/// is not applied): the cut top's or a claw hole's; in *hole, when given,
/// that claw hole or -1 for the top.
inline double RimDistance(const Eigen::Vector3f& p, const ProtocolHoles& h, int* hole = nullptr) {
  double d = std::abs(h.top_z - p.z());
  if (hole != nullptr) *hole = -1;
  for (size_t i = 0; i < h.dirs.size(); ++i) {
    const Eigen::Vector2d& dir = h.dirs[i];
    if (dir.x() * p.x() + dir.y() * p.y() <= 0.0) continue;
    const double t = dir.x() * p.y() - dir.y() * p.x();
    const double dh =
        RectDistance(t, p.z(), h.half_width, h.z_centre - h.half_height, h.z_centre + h.half_height);
    if (dh < d) {
      d = dh;
      if (hole != nullptr) *hole = static_cast<int>(i);
    }
  }
  return d;
}

/// The hole-boundary points a perfect detector would give: indices of the
/// cloud points (given in O) within `width_m` of the cut top or of a claw
/// patch.
inline std::vector<int> OracleBoundary(const PointList& points_O, const ProtocolHoles& h,
                                       double width_m = 0.002) {
  std::vector<int> out;
  for (size_t k = 0; k < points_O.size(); ++k) {
    const Eigen::Vector3f& p = points_O[k];
    bool near = p.z() > h.top_z - width_m;
    for (size_t i = 0; i < h.dirs.size() && !near; ++i) near = WithinPatch(h, i, p, width_m);
    if (near) out.push_back(static_cast<int>(k));
  }
  return out;
}

/// Arc-length parameter of (a, b) projected on the polyline `poly`.
inline double PolylineParam(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  double best = 1e18, best_u = 0, run = 0;
  for (size_t s = 0; s + 1 < poly.size(); ++s) {
    const Eigen::Vector2d e = poly[s + 1] - poly[s];
    const double len = e.norm();
    const double t = std::clamp((q - poly[s]).dot(e) / (len * len), 0.0, 1.0);
    const double d = (poly[s] + t * e - q).norm();
    if (d < best) best = d, best_u = run + t * len;
    run += len;
  }
  return best_u;
}

/// Orders the boundary points (indices into points_O) along the analytic
/// outlines of a straight grasp, as linking would: a top grasp gives one
/// closed line (the rim, dipping into each claw hole's U in turn, counter-
/// clockwise); a middle grasp gives the closed rim and one closed line per
/// claw hole. Points within `rim_band_m` of the top count as rim.
inline std::vector<BoundaryLine> OrderedLines(const PointList& points_O, const std::vector<int>& boundary,
                                              const ProtocolHoles& h, double rim_band_m = 0.002) {
  const double hw = h.half_width, hh = h.half_height;
  const double top_b = h.top_z - h.z_centre;
  const std::vector<Eigen::Vector2d> u_path = {{-hw, top_b}, {-hw, -hh}, {hw, -hh}, {hw, top_b}};
  const std::vector<Eigen::Vector2d> ring = {{-hw, hh}, {-hw, -hh}, {hw, -hh}, {hw, hh}, {-hw, hh}};
  // (angle, parameter along the claw outline, index); one list per line.
  using Key = std::pair<std::pair<double, double>, int>;
  std::vector<std::vector<Key>> keyed(h.top_grasp ? 1 : 1 + h.dirs.size());
  for (int k : boundary) {
    const Eigen::Vector3f& p = points_O[static_cast<size_t>(k)];
    if (p.z() > h.top_z - rim_band_m) {
      keyed[0].push_back({{std::atan2(p.y(), p.x()), 0.0}, k});
      continue;
    }
    for (size_t i = 0; i < h.dirs.size(); ++i) {
      const PatchCoords c = InPatch(h, i, p);
      if (!c.front || std::abs(c.a) > hw + 0.004 || std::abs(c.b) > hh + 0.004) continue;
      const Eigen::Vector2d q(c.a, c.b);
      const double angle = std::atan2(h.dirs[i].y(), h.dirs[i].x());
      if (h.top_grasp) {
        keyed[0].push_back({{angle, PolylineParam(u_path, q)}, k});
      } else {
        keyed[1 + i].push_back({{0.0, PolylineParam(ring, q)}, k});
      }
      break;
    }
  }
  std::vector<BoundaryLine> lines;
  for (std::vector<Key>& list : keyed) {
    std::sort(list.begin(), list.end());
    BoundaryLine line;
    line.closed = true;
    for (const Key& key : list) line.indices.push_back(key.second);
    lines.push_back(std::move(line));
  }
  return lines;
}

/// Swaps neighbouring entries with probability `p` (a linker's zig-zag
/// across a boundary band two points wide).
inline void JitterOrder(std::vector<int>* indices, double p, uint64_t seed) {
  Rng rng(seed);
  for (size_t i = 0; i + 1 < indices->size(); ++i) {
    if (rng.Uniform() < p) {
      std::swap((*indices)[i], (*indices)[i + 1]);
      ++i;
    }
  }
}

inline PointList Transformed(const PointList& points, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  PointList out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) out.push_back(Tf * p);
  return out;
}

inline PointList Gather(const PointList& points, const std::vector<int>& indices) {
  PointList out;
  for (int i : indices) out.push_back(points[static_cast<size_t>(i)]);
  return out;
}

}  // namespace graspfill::repair::testing
