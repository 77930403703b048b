// SPDX-License-Identifier: BSD-3-Clause
// A claw holding a sphere in front of a camera, rendered with Embree (the
// claw) and analytically (the sphere, the wall behind), with 1 mm of
// Gaussian depth noise: the frames the refinement tests register against.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/core/raycaster.hpp"
#include "graspfill/types.hpp"

namespace graspfill::testing {

constexpr double kSphereRadiusM = 0.035;
const Eigen::Vector3d kSphereCentreG(0.0, 0.0, 0.045);
constexpr double kOpeningM = 0.0355;

inline TriangleMesh PosedClaw() { return claw::ClawModel::ThreeFinger().Posed(kOpeningM); }

/// The gripper pointing down, 0.55 m in front of the camera, seen from 25
/// deg below, turned by `theta_rad` about its approach axis.
inline Eigen::Isometry3d TrueT_C_G(double theta_rad) {
  Eigen::Matrix3d R0;
  R0.col(0) = Eigen::Vector3d(1, 0, 0);
  R0.col(2) = Eigen::Vector3d(0, 1, 0);
  R0.col(1) = R0.col(2).cross(R0.col(0));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(-25.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * R0 *
               Eigen::AngleAxisd(theta_rad, Eigen::Vector3d::UnitZ());
  T.translation() = Eigen::Vector3d(0.0, 0.0, 0.55) - T.linear() * kSphereCentreG;
  return T;
}

/// Depth of claw + sphere + a wall at 1.2 m, noise `sigma_m` (seeded).
/// `with_claw` false renders the sphere and wall only.
inline DepthFrame RenderFrame(const Raycaster& claw_G, const Eigen::Isometry3d& T_C_G, double sigma_m,
                              unsigned seed, bool with_claw = true) {
  DepthFrame f;
  const CameraIntrinsics& K = f.intrinsics;
  f.depth_m.assign(static_cast<size_t>(K.width) * K.height, 0.0f);
  const Eigen::Isometry3d T_G_C = T_C_G.inverse();
  const Eigen::Vector3d c_C = T_C_G * kSphereCentreG;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      double z = 1.2;
      const double a = ray.squaredNorm(), b = -2.0 * ray.dot(c_C);
      const double disc = b * b - 4 * a * (c_C.squaredNorm() - kSphereRadiusM * kSphereRadiusM);
      if (disc >= 0) z = std::min(z, (-b - std::sqrt(disc)) / (2 * a));
      if (with_claw) {
        const Eigen::Vector3d dir_G = T_G_C.linear() * ray.normalized();
        const RayHit hit = claw_G.Cast(T_G_C.translation().cast<float>(), dir_G.cast<float>());
        if (hit.hit()) z = std::min(z, hit.t / std::sqrt(a));
      }
      f.depth_m[static_cast<size_t>(v) * K.width + u] = static_cast<float>(z + noise(rng));
    }
  }
  return f;
}

/// A rigid motion of C: `mm` in direction `t_dir`, `deg` about `axis`.
inline Eigen::Isometry3d CameraError(double mm, const Eigen::Vector3d& t_dir, double deg,
                                     const Eigen::Vector3d& axis) {
  Eigen::Isometry3d E = Eigen::Isometry3d::Identity();
  E.linear() = Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  E.translation() = 0.001 * mm * t_dir.normalized();
  return E;
}

/// How far two poses put the claw's centre apart [m], and their angle [deg].
inline double ClawOffsetM(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Vector3d centre_G(0.0, 0.0, 0.04);
  return (a * centre_G - b * centre_G).norm();
}
inline double AngleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

}  // namespace graspfill::testing
