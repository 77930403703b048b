// SPDX-License-Identifier: BSD-3-Clause
#include "synth/internal/zoo_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "synth/internal/ring_stack.hpp"

namespace graspfill::synth::internal {
namespace {

int QuarterFacets(int segments) { return std::max(2, segments / 4); }

// An ellipse of semi-axes (rx, ry) at height z, n points counter-clockwise
// from +x: point 0 is exactly on +x, and n divisible by 4 puts points
// exactly on the other axes too, so the bounding box is exact.
Ring Ellipse(double rx, double ry, double z, int n) {
  Ring ring;
  ring.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double phi = 2.0 * M_PI * i / n;
    ring.emplace_back(rx * std::cos(phi), ry * std::sin(phi), z);
  }
  return ring;
}

Ring Pole(const Eigen::Vector3d& p, int n) { return Ring(n, p); }

// --- rounded box -----------------------------------------------------------

double EdgeRadius(const Eigen::Vector3d& size_m) { return kRoundedBoxEdgeFraction * size_m.minCoeff(); }

// Horizontal section of the rounded box: the core rectangle (half sides
// hx, hy) grown by rho, as four quarter arcs of m facets each. At rho = 0
// each arc collapses onto its core corner, exactly (0 * cos = 0).
Ring RoundedRectangle(double hx, double hy, double rho, double z, int m) {
  const double cx[4] = {hx, -hx, -hx, hx};
  const double cy[4] = {hy, hy, -hy, -hy};
  Ring ring;
  ring.reserve(4 * (m + 1));
  for (int q = 0; q < 4; ++q) {
    for (int j = 0; j <= m; ++j) {
      const double beta = 0.5 * M_PI * (q + static_cast<double>(j) / m);
      ring.emplace_back(cx[q] + rho * std::cos(beta), cy[q] + rho * std::sin(beta), z);
    }
  }
  return ring;
}

// --- blob --------------------------------------------------------------------

// Lobe amplitudes (fractions of the unit radius) and phases [rad]. They
// add up to 7.5%; the odd and rotated terms leave no mirror plane.
constexpr double kThreeLobes = 0.03;  // sin^3(theta) cos(3 phi - phase)
constexpr double kThreeLobesPhase = 0.5;
constexpr double kLean = 0.02;  // sin(2 theta) cos(phi - azimuth)
constexpr double kLeanAzimuth = 1.1;
constexpr double kFlattening = 0.015;  // Legendre P2(cos theta)
constexpr double kTopBottom = 0.01;    // Legendre P3(cos theta)

// Polynomials in u, so the surface is smooth at the poles too.
Eigen::Vector3d UnitBlobPoint(const Eigen::Vector3d& u) {
  const double x = u.x(), y = u.y(), z = u.z();
  const double three = std::cos(kThreeLobesPhase) * (x * x * x - 3.0 * x * y * y) +
                       std::sin(kThreeLobesPhase) * (3.0 * x * x * y - y * y * y);
  const double lean = 2.0 * z * (std::cos(kLeanAzimuth) * x + std::sin(kLeanAzimuth) * y);
  const double p2 = 0.5 * (3.0 * z * z - 1.0);
  const double p3 = 0.5 * z * (5.0 * z * z - 3.0);
  const double r = 1.0 + kThreeLobes * three + kLean * lean + kFlattening * p2 + kTopBottom * p3;
  return r * u;
}

// Unit direction at polar angle theta from -z (the stack goes up) and
// azimuth phi from +x.
Eigen::Vector3d Direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), -std::cos(theta)};
}

// max over the unit blob of d . p: a 2-degree grid, then three 10x zooms
// of a 21 x 21 grid spanning one step either side of the best point.
double UnitBlobSupport(const Eigen::Vector3d& d) {
  auto value = [&d](double theta, double phi) { return d.dot(UnitBlobPoint(Direction(theta, phi))); };
  constexpr int kCoarse = 90;
  double step = M_PI / kCoarse;
  double best = -std::numeric_limits<double>::infinity();
  double best_theta = 0.0;
  double best_phi = 0.0;
  for (int i = 0; i <= kCoarse; ++i) {
    for (int k = 0; k < 2 * kCoarse; ++k) {
      const double v = value(i * step, k * step);
      if (v > best) {
        best = v;
        best_theta = i * step;
        best_phi = k * step;
      }
    }
  }
  for (int zoom = 0; zoom < 3; ++zoom) {
    step /= 10.0;
    const double theta0 = best_theta;
    const double phi0 = best_phi;
    for (int i = -10; i <= 10; ++i) {
      for (int k = -10; k <= 10; ++k) {
        const double v = value(theta0 + i * step, phi0 + k * step);
        if (v > best) {
          best = v;
          best_theta = theta0 + i * step;
          best_phi = phi0 + k * step;
        }
      }
    }
  }
  return best;
}

// The affine map taking the unit blob's exact bounding box to the object
// frame's W x D x H box.
struct BlobFit {
  Eigen::Vector3d offset;  // unit-blob point that maps to the origin
  Eigen::Vector3d scale;
  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const { return (p - offset).cwiseProduct(scale); }
};

BlobFit FitBlob(const Eigen::Vector3d& size_m) {
  Eigen::Vector3d lo;
  Eigen::Vector3d hi;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
    hi[axis] = UnitBlobSupport(e);
    lo[axis] = -UnitBlobSupport(-e);
  }
  BlobFit fit;
  fit.offset = 0.5 * (lo + hi);
  fit.offset.z() = lo.z();  // z from 0, x and y centred
  fit.scale = size_m.cwiseQuotient(hi - lo);
  return fit;
}

// Volume of the unit blob, (1/3) integral of r^3 over directions: midpoint
// rule in theta (error ~ step^2), trapezoid in phi (exact for the lobes'
// low-order trigonometric terms).
double UnitBlobVolume() {
  constexpr int kTheta = 512;
  constexpr int kPhi = 128;
  const double dtheta = M_PI / kTheta;
  const double dphi = 2.0 * M_PI / kPhi;
  double sum = 0.0;
  for (int i = 0; i < kTheta; ++i) {
    const double theta = (i + 0.5) * dtheta;
    for (int k = 0; k < kPhi; ++k) {
      const double r = UnitBlobPoint(Direction(theta, k * dphi)).norm();
      sum += r * r * r * std::sin(theta);
    }
  }
  return sum * dtheta * dphi / 3.0;
}

// --- mug ---------------------------------------------------------------------

struct MugGeometry {
  double body_radius;
  double body_centre_x;
  double tube_radius;
  double path_x;   // x of the path's ends (its ellipse's centre)
  double path_z;   // z of the ellipse's centre
  double path_rx;  // semi-axes of the half ellipse
  double path_rz;
};

MugGeometry Mug(const Eigen::Vector3d& size_m) {
  const double w = size_m.x();
  const double d = size_m.y();
  const double h = size_m.z();
  MugGeometry g;
  g.body_radius = 0.5 * d;
  g.body_centre_x = 0.5 * (d - w);
  const double reach = w - d;
  g.tube_radius = kMugTubeFraction * reach;
  // The flat end's rim (radius tube_radius, in a plane x = path_x) is
  // inside the round body once the end sinks tube_radius^2 / (2 R); twice
  // that leaves a margin for the body's facets.
  const double sink = g.tube_radius * g.tube_radius / g.body_radius;
  g.path_x = g.body_centre_x + g.body_radius - sink;
  g.path_z = 0.5 * h;
  g.path_rx = 0.5 * w - g.tube_radius - g.path_x;  // outer side on x = W/2
  g.path_rz = kMugHandleHeightFraction * h;
  // Smallest radius of curvature of the half ellipse (at an end or at the
  // apex) must exceed the tube's, or the tube folds onto itself.
  const double min_curvature_radius =
      std::min(g.path_rx * g.path_rx / g.path_rz, g.path_rz * g.path_rz / g.path_rx);
  const bool fits = reach > 0.0 && g.tube_radius < g.body_radius && g.path_rz + g.tube_radius <= 0.5 * h &&
                    min_curvature_radius > g.tube_radius;
  if (!fits) {
    throw std::invalid_argument("mug: the handle does not fit a " + std::to_string(w) + " x " +
                                std::to_string(d) + " x " + std::to_string(h) +
                                " m box (needs W > D, roughly 0.1 H < W - D < 0.75 H)");
  }
  return g;
}

// Length of the half ellipse: its integrand has period pi, so the
// trapezoid rule over one period converges geometrically.
double HalfEllipseLength(double rx, double rz) {
  constexpr int kSteps = 256;
  double sum = 0.0;
  for (int k = 0; k < kSteps; ++k) {
    const double a = M_PI * k / kSteps;
    sum += std::hypot(rx * std::sin(a), rz * std::cos(a));
  }
  return sum * M_PI / kSteps;
}

}  // namespace

TriangleMesh MakeRoundedBox(const Eigen::Vector3d& size_m, int segments) {
  const int m = QuarterFacets(segments);
  const double e = EdgeRadius(size_m);
  const double hx = 0.5 * size_m.x() - e;
  const double hy = 0.5 * size_m.y() - e;
  const double z_low = e;  // core box spans [e, H - e]
  const double z_high = size_m.z() - e;
  const int n = 4 * (m + 1);
  std::vector<Ring> rings = {Pole({0.0, 0.0, 0.0}, n)};
  // Latitude psi = 90 degrees * j / m on the lower, then the upper rounding;
  // rho is set to exactly 0 at the faces (cos(pi / 2) is not).
  for (int j = m; j >= 0; --j) {
    const double psi = 0.5 * M_PI * j / m;
    const double rho = j == m ? 0.0 : e * std::cos(psi);
    rings.push_back(RoundedRectangle(hx, hy, rho, z_low - e * std::sin(psi), m));
  }
  for (int j = 0; j <= m; ++j) {
    const double psi = 0.5 * M_PI * j / m;
    const double rho = j == m ? 0.0 : e * std::cos(psi);
    rings.push_back(RoundedRectangle(hx, hy, rho, z_high + e * std::sin(psi), m));
  }
  rings.push_back(Pole({0.0, 0.0, size_m.z()}, n));
  return RingStackMesh(rings);
}

double RoundedBoxVolume(const Eigen::Vector3d& size_m) {
  const double e = EdgeRadius(size_m);
  const double a = size_m.x() - 2.0 * e;
  const double b = size_m.y() - 2.0 * e;
  const double c = size_m.z() - 2.0 * e;
  return a * b * c + 2.0 * e * (a * b + b * c + c * a) + M_PI * e * e * (a + b + c) +
         4.0 / 3.0 * M_PI * e * e * e;
}

TriangleMesh MakeBottle(const Eigen::Vector3d& size_m, int segments) {
  const double w = size_m.x();
  const double h = size_m.z();
  const double y_per_x = size_m.y() / w;  // elliptic sections for D != W
  const double body_r = 0.5 * w;
  const double neck_r = 0.5 * kBottleNeckFraction * w;
  const double shoulder_z0 = kBottleBodyFraction * h;
  const double shoulder_len = kBottleShoulderFraction * h;
  auto section = [&](double r, double z) { return Ellipse(r, y_per_x * r, z, segments); };
  std::vector<Ring> rings = {Pole({0.0, 0.0, 0.0}, segments), section(body_r, 0.0)};
  const int m = QuarterFacets(segments);
  for (int j = 0; j <= m; ++j) {
    const double s = static_cast<double>(j) / m;
    const double r = neck_r + (body_r - neck_r) * 0.5 * (1.0 + std::cos(M_PI * s));
    rings.push_back(section(r, shoulder_z0 + s * shoulder_len));
  }
  rings.push_back(section(neck_r, h));
  rings.push_back(Pole({0.0, 0.0, h}, segments));
  return RingStackMesh(rings);
}

double BottleVolume(const Eigen::Vector3d& size_m) {
  const double w = size_m.x();
  const double h = size_m.z();
  const double body_r = 0.5 * w;
  const double neck_r = 0.5 * kBottleNeckFraction * w;
  // Shoulder r = a + b cos(pi s), s in [0, 1]: the mean of r^2 is a^2 + b^2 / 2.
  const double a = 0.5 * (body_r + neck_r);
  const double b = 0.5 * (body_r - neck_r);
  const double neck_len = (1.0 - kBottleBodyFraction - kBottleShoulderFraction) * h;
  const double circular =
      M_PI * (body_r * body_r * kBottleBodyFraction * h +
              (a * a + 0.5 * b * b) * kBottleShoulderFraction * h + neck_r * neck_r * neck_len);
  return circular * size_m.y() / w;
}

TriangleMesh MakeBlob(const Eigen::Vector3d& size_m, int segments) {
  const BlobFit fit = FitBlob(size_m);
  const int lat = std::max(4, segments / 2);  // latitude steps, pole to pole
  std::vector<Ring> rings = {Pole(fit.Apply(UnitBlobPoint({0.0, 0.0, -1.0})), segments)};
  for (int k = 1; k < lat; ++k) {
    const double theta = M_PI * k / lat;
    Ring ring;
    ring.reserve(segments);
    for (int i = 0; i < segments; ++i) {
      ring.push_back(fit.Apply(UnitBlobPoint(Direction(theta, 2.0 * M_PI * i / segments))));
    }
    rings.push_back(std::move(ring));
  }
  rings.push_back(Pole(fit.Apply(UnitBlobPoint({0.0, 0.0, 1.0})), segments));
  return RingStackMesh(rings);
}

double BlobVolume(const Eigen::Vector3d& size_m) {
  const BlobFit fit = FitBlob(size_m);
  return UnitBlobVolume() * fit.scale.prod();
}

TriangleMesh MakeMug(const Eigen::Vector3d& size_m, int segments) {
  const MugGeometry g = Mug(size_m);
  const double h = size_m.z();
  // Body: a cylinder on the axis x = body_centre_x, lid and bottom flat.
  const Eigen::Vector3d shift(g.body_centre_x, 0.0, 0.0);
  std::vector<Ring> body = {Pole(shift, segments), Ellipse(g.body_radius, g.body_radius, 0.0, segments),
                            Ellipse(g.body_radius, g.body_radius, h, segments),
                            Pole(shift + Eigen::Vector3d(0.0, 0.0, h), segments)};
  for (size_t k = 1; k + 1 < body.size(); ++k) {
    for (Eigen::Vector3d& p : body[k]) p += shift;
  }
  TriangleMesh mesh = RingStackMesh(body);

  // Handle: path angle alpha from -90 degrees (lower end) to +90 (upper
  // end) through the apex on +x. Frame per ring: n1 in the x-z plane,
  // n2 = +y, n1 x n2 = the tangent, so each ring runs counter-clockwise
  // about the direction of travel.
  const int steps = std::max(8, segments / 2);
  const int around = std::max(8, segments / 2);
  std::vector<Ring> tube;
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k <= steps; ++k) {
    const double alpha = M_PI * (static_cast<double>(k) / steps - 0.5);
    const Eigen::Vector3d c(g.path_x + g.path_rx * std::cos(alpha), 0.0,
                            g.path_z + g.path_rz * std::sin(alpha));
    const Eigen::Vector3d t =
        Eigen::Vector3d(-g.path_rx * std::sin(alpha), 0.0, g.path_rz * std::cos(alpha)).normalized();
    const Eigen::Vector3d n1(t.z(), 0.0, -t.x());
    const Eigen::Vector3d n2 = Eigen::Vector3d::UnitY();
    Ring ring;
    ring.reserve(around);
    for (int i = 0; i < around; ++i) {
      const double phi = 2.0 * M_PI * i / around;
      ring.push_back(c + g.tube_radius * (std::cos(phi) * n1 + std::sin(phi) * n2));
    }
    centres.push_back(c);
    tube.push_back(std::move(ring));
  }
  tube.insert(tube.begin(), Pole(centres.front(), around));
  tube.push_back(Pole(centres.back(), around));
  mesh.Append(RingStackMesh(tube));
  return mesh;
}

double MugVolume(const Eigen::Vector3d& size_m) {
  const MugGeometry g = Mug(size_m);
  const double body = M_PI * g.body_radius * g.body_radius * size_m.z();
  const double tube = M_PI * g.tube_radius * g.tube_radius * HalfEllipseLength(g.path_rx, g.path_rz);
  return body + tube;
}

double BowlWall(const Eigen::Vector3d& size_m) {
  const double smallest = std::min({0.5 * size_m.x(), 0.5 * size_m.y(), size_m.z()});
  return std::min(kBowlWallM, kBowlMaxWallFraction * smallest);
}

TriangleMesh MakeBowl(const Eigen::Vector3d& size_m, int segments) {
  const double a = 0.5 * size_m.x();
  const double b = 0.5 * size_m.y();
  const double h = size_m.z();
  const double t = BowlWall(size_m);
  const int m = QuarterFacets(segments);
  // Latitude psi from -90 degrees (bottom) to 0 (rim) on a half ellipsoid
  // centred at the rim's height: outer surface up, then inner one down.
  auto half_ellipsoid_ring = [&](double ra, double rb, double rz, int j) {
    const double psi = 0.5 * M_PI * (static_cast<double>(j) / m - 1.0);
    return Ellipse(ra * std::cos(psi), rb * std::cos(psi), h + rz * std::sin(psi), segments);
  };
  std::vector<Ring> rings = {Pole({0.0, 0.0, 0.0}, segments)};
  for (int j = 1; j <= m; ++j) rings.push_back(half_ellipsoid_ring(a, b, h, j));
  for (int j = m; j >= 1; --j) rings.push_back(half_ellipsoid_ring(a - t, b - t, h - t, j));
  rings.push_back(Pole({0.0, 0.0, t}, segments));
  return RingStackMesh(rings);
}

double BowlVolume(const Eigen::Vector3d& size_m) {
  const double a = 0.5 * size_m.x();
  const double b = 0.5 * size_m.y();
  const double h = size_m.z();
  const double t = BowlWall(size_m);
  return 2.0 / 3.0 * M_PI * (a * b * h - (a - t) * (b - t) * (h - t));
}

}  // namespace graspfill::synth::internal
