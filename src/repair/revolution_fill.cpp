// SPDX-License-Identifier: BSD-3-Clause
#include "revolution_fill.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace graspfill::repair {
namespace {

// The radial distance of p from the surface.
double RadialResidual(const Revolution& s, const Eigen::Vector3f& p) {
  const double r = std::hypot(p.x() - s.x0, p.y() - s.y0);
  return std::abs(r - std::sqrt(std::max(0.0, s.RadiusSquared(p.z()))));
}

// The lowest root of r^2 above `top_z` (NaN when r^2 never reaches 0 there).
double PoleAbove(const Revolution& s, double top_z) {
  if (!(s.RadiusSquared(top_z) > 0.0)) return std::nan("");
  if (std::abs(s.c) < 1e-12) return s.b < 0.0 ? -s.a / s.b : std::nan("");
  const double disc = s.b * s.b - 4.0 * s.c * s.a;
  if (disc < 0.0) return std::nan("");
  const double q = std::sqrt(disc);
  double best = std::nan("");
  for (double z : {(-s.b - q) / (2.0 * s.c), (-s.b + q) / (2.0 * s.c)}) {
    if (z > top_z && !(best <= z)) best = z;
  }
  return best;
}

}  // namespace

Eigen::Vector3f Revolution::Normal(const Eigen::Vector3f& p) const {
  const Eigen::Vector3d gradient(p.x() - x0, p.y() - y0, -0.5 * (b + 2.0 * c * p.z()));
  const double norm = gradient.norm();
  if (!(norm > 0.0)) return Eigen::Vector3f::Zero();
  return (gradient / norm).cast<float>();
}

std::optional<Revolution> FitRevolution(const PointList& points_V, double top_z, double reach_m) {
  if (points_V.size() < 20) return std::nullopt;
  std::vector<double> weight(points_V.size(), 1.0), residual(points_V.size(), 0.0);
  Revolution s;
  // Two reweightings: the first fit's 3-RMS band keeps the body and drops
  // what belongs to another part (a stem, a handle); the second refits.
  for (int pass = 0; pass < 3; ++pass) {
    Eigen::Matrix<double, 5, 5> normal = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
    for (size_t i = 0; i < points_V.size(); ++i) {
      if (weight[i] == 0.0) continue;
      const Eigen::Vector3d p = points_V[i].cast<double>();
      Eigen::Matrix<double, 5, 1> row;
      row << 2.0 * p.x(), 2.0 * p.y(), 1.0, p.z(), p.z() * p.z();
      normal += row * row.transpose();
      rhs += row * (p.x() * p.x() + p.y() * p.y());
    }
    const Eigen::Matrix<double, 5, 1> u = normal.ldlt().solve(rhs);
    if (!u.allFinite()) return std::nullopt;
    s.x0 = u(0);
    s.y0 = u(1);
    s.a = u(2) + s.x0 * s.x0 + s.y0 * s.y0;
    s.b = u(3);
    s.c = u(4);
    // Each point's residual once (the last pass needs only the inliers').
    double squares = 0.0;
    size_t used = 0;
    for (size_t i = 0; i < points_V.size(); ++i) {
      if (weight[i] == 0.0 && pass == 2) continue;
      residual[i] = RadialResidual(s, points_V[i]);
      if (weight[i] == 0.0) continue;
      squares += std::pow(residual[i], 2);
      ++used;
    }
    if (used < 20) return std::nullopt;
    s.rms_m = std::sqrt(squares / static_cast<double>(used));
    if (pass == 2) break;
    for (size_t i = 0; i < points_V.size(); ++i) weight[i] = residual[i] <= 3.0 * s.rms_m ? 1.0 : 0.0;
  }
  s.pole_z = PoleAbove(s, top_z);
  if (!(s.pole_z <= top_z + reach_m)) return std::nullopt;
  return s;
}

RevolutionSamples SampleRevolution(const Revolution& s, double from_z, double spacing_m, double hole_m,
                                   const PointList& taken_V) {
  RevolutionSamples out;
  if (!(spacing_m > 0.0) || !(s.pole_z > from_z)) return out;
  // Rings one spacing apart along the profile (dz shrinks where the
  // surface turns flat towards the pole), then the pole itself, a ring of
  // one.
  struct Ring {
    float z;
    size_t first;               // its first sample in `samples`
    long n;                     // its samples
    double radius, per_sample;  // [m], [rad]
  };
  std::vector<Ring> rings;
  PointList samples;
  double z = from_z;
  while (z < s.pole_z) {
    const double r2 = s.RadiusSquared(z);
    if (!(r2 > 0.0)) {
      if (!(s.b + 2.0 * s.c * z > 0.0)) break;  // past the pole
      z += 0.25 * spacing_m;                    // under the far pole: rise to it
      continue;
    }
    const double r = std::sqrt(r2);
    const int n = std::max(1, static_cast<int>(std::ceil(2.0 * M_PI * r / spacing_m)));
    rings.push_back({static_cast<float>(z), samples.size(), n, r, 2.0 * M_PI / n});
    for (int k = 0; k < n; ++k) {
      const double t = 2.0 * M_PI * k / n;
      samples.emplace_back(static_cast<float>(s.x0 + r * std::cos(t)),
                           static_cast<float>(s.y0 + r * std::sin(t)), static_cast<float>(z));
    }
    const double slope = (s.b + 2.0 * s.c * z) / (2.0 * r);  // dr/dz
    z += std::max(spacing_m / std::sqrt(1.0 + slope * slope), 1e-6);
  }
  rings.push_back({static_cast<float>(s.pole_z), samples.size(), 1, 0.0, 2.0 * M_PI});
  samples.emplace_back(static_cast<float>(s.x0), static_cast<float>(s.y0), static_cast<float>(s.pole_z));

  // A sample within a spacing of a taken point moved radially onto the
  // surface lies on the seen surface (so the model's own error off it, a
  // ball's panels, opens no hole). Asked from the taken points' side: each
  // reaches the few samples of the rings within a spacing, by its angle.
  PointList on_surface;
  on_surface.reserve(taken_V.size());
  std::vector<char> covered(samples.size(), 0);
  const double spacing2 = spacing_m * spacing_m;
  for (const Eigen::Vector3f& p : taken_V) {
    const double r2 = s.RadiusSquared(p.z());
    const Eigen::Vector2d d(p.x() - s.x0, p.y() - s.y0);
    if (!(r2 > 0.0) || d.norm() < 1e-9) continue;
    const Eigen::Vector2d q2 = Eigen::Vector2d(s.x0, s.y0) + d.normalized() * std::sqrt(r2);
    const Eigen::Vector3f q(static_cast<float>(q2.x()), static_cast<float>(q2.y()), p.z());
    on_surface.push_back(q);
    const Eigen::Vector3d qd = q.cast<double>();
    const auto test = [&](size_t j) {
      if (!covered[j] && (samples[j].cast<double>() - qd).squaredNorm() <= spacing2) covered[j] = 1;
    };
    const double angle = std::atan2(qd.y() - s.y0, qd.x() - s.x0);
    const double q_radius = std::hypot(qd.x() - s.x0, qd.y() - s.y0);
    auto ring = std::lower_bound(rings.begin(), rings.end(), q.z() - spacing_m - 1e-6,
                                 [](const Ring& a, double v) { return a.z < v; });
    for (; ring != rings.end() && ring->z <= q.z() + spacing_m + 1e-6; ++ring) {
      const long n = ring->n;
      // Within a spacing, the angle to a sample at radius r is at most
      // 2 asin(spacing / (2 sqrt(r q_radius))) <= pi spacing / (2 sqrt(r
      // q_radius)); one sample more each side for the rounding, and the
      // exact test decides.
      const double reach = M_PI * spacing_m / (2.0 * std::sqrt(ring->radius * q_radius));
      const double per_reach = reach / ring->per_sample;
      const long half = per_reach < static_cast<double>(n) ? static_cast<long>(per_reach) + 2 : n;
      if (2 * half + 1 >= n) {
        for (long k = 0; k < n; ++k) test(ring->first + static_cast<size_t>(k));
        continue;
      }
      long k = std::lround(angle / ring->per_sample) - half;
      if (k < 0) k += n;
      for (long m = 0; m <= 2 * half; ++m, ++k) {
        if (k >= n) k -= n;
        test(ring->first + static_cast<size_t>(k));
      }
    }
  }
  std::optional<NeighborIndex> taken;
  for (size_t j = 0; j < samples.size(); ++j) {
    if (covered[j]) continue;
    if (!taken && !on_surface.empty()) taken.emplace(on_surface);
    out.points_V.push_back(samples[j]);
    out.in_hole.push_back(!taken || !taken->AnyWithin(samples[j], hole_m));
  }
  return out;
}

}  // namespace graspfill::repair
