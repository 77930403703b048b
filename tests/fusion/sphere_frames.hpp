// SPDX-License-Identifier: BSD-3-Clause
// A sphere seen by a camera turning around it: exact z-depth frames for the
// fusion tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "graspfill/types.hpp"

namespace graspfill::fusion {

inline constexpr double kSphereRadiusM = 0.04;
inline const Eigen::Vector3d kSphereCentreG(0.0, 0.0, 0.08);

// Camera 0.5 m from the sphere, turned about G's z by `angle` and raised
// by `elevation` [rad], looking at it: T_C_G.
inline Eigen::Isometry3d SphereCameraPose(double angle, double elevation = 0.0) {
  const Eigen::Vector3d eye_G =
      kSphereCentreG + 0.5 * Eigen::Vector3d(std::cos(angle) * std::cos(elevation),
                                             std::sin(angle) * std::cos(elevation), std::sin(elevation));
  const Eigen::Vector3d z = (kSphereCentreG - eye_G).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d T_G_C = Eigen::Isometry3d::Identity();
  T_G_C.linear().col(0) = x;
  T_G_C.linear().col(1) = z.cross(x);
  T_G_C.linear().col(2) = z;
  T_G_C.translation() = eye_G;
  return T_G_C.inverse();
}

// Exact z-depth image of the sphere (ray-sphere intersection; 0 where the
// ray misses it).
inline DepthFrame RenderSphere(const Eigen::Isometry3d& T_C_G, const CameraIntrinsics& K = {}) {
  DepthFrame f;
  f.intrinsics = K;
  f.depth_m.assign(static_cast<size_t>(K.width) * K.height, 0.0f);
  const Eigen::Vector3d c = T_C_G * kSphereCentreG;
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const double a = ray.squaredNorm(), b = -2.0 * ray.dot(c);
      const double disc = b * b - 4 * a * (c.squaredNorm() - kSphereRadiusM * kSphereRadiusM);
      if (disc < 0) continue;
      f.depth_m[static_cast<size_t>(v) * K.width + u] = static_cast<float>((-b - std::sqrt(disc)) / (2 * a));
    }
  }
  return f;
}

}  // namespace graspfill::fusion
