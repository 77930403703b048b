// SPDX-License-Identifier: BSD-3-Clause
// The pipeline tests' analytic scene: a sphere held by the three-finger
// claw, seen by a fixed camera while the gripper turns.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "graspfill/core/raycaster.hpp"
#include "graspfill/pipeline/pipeline.hpp"

namespace graspfill {

constexpr double kRadiusM = 0.035;
inline const Eigen::Vector3d kCentreG(0.0, 0.0, 0.045);  // top 1 cm below the palm
constexpr double kOpeningM = 0.0355;                     // fingers touch the equator... roughly

inline claw::ClawModel Claw() { return claw::ClawModel::ThreeFinger(); }

// Gripper approach axis pointing down-ish, turning about its z over time.
inline Eigen::Isometry3d T_C_G_at(double t_s) {
  Eigen::Isometry3d T_W_G = Eigen::Isometry3d::Identity();
  // World: camera looks along +x_W, z_W up. The gripper's z points down.
  T_W_G.linear() = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(1.5 * t_s, Eigen::Vector3d::UnitZ()))
                       .toRotationMatrix();
  T_W_G.translation() = Eigen::Vector3d(0.55, 0.0, 0.20);
  // Camera 15 cm below the object centre, looking at it (slightly upward).
  const Eigen::Vector3d eye(0.0, 0.0, 0.0);
  const Eigen::Vector3d target = T_W_G * kCentreG;
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  T_W_C.linear().col(0) = x;
  T_W_C.linear().col(1) = z.cross(x);
  T_W_C.linear().col(2) = z;
  T_W_C.translation() = eye;
  return T_W_C.inverse() * T_W_G;
}

// Exact depth of the sphere + claw (claw by Embree, sphere analytically).
// A sphere radius of 0: the claw alone.
inline DepthFrame Render(const Raycaster& claw_G, const Eigen::Isometry3d& T_C_G, int64_t utime,
                         const CameraIntrinsics& intrinsics = CameraIntrinsics{},
                         double sphere_radius_m = kRadiusM) {
  DepthFrame f;
  f.utime = utime;
  f.intrinsics = intrinsics;
  const CameraIntrinsics& K = f.intrinsics;
  f.depth_m.assign(K.width * K.height, 0.0f);
  const Eigen::Isometry3d T_G_C = T_C_G.inverse();
  const Eigen::Vector3d c_C = T_C_G * kCentreG;
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      double z = 1.5;  // background wall, outside the workspace
      const double a = ray.squaredNorm(), b = -2.0 * ray.dot(c_C);
      const double disc = b * b - 4 * a * (c_C.squaredNorm() - sphere_radius_m * sphere_radius_m);
      if (sphere_radius_m > 0 && disc >= 0) z = std::min(z, (-b - std::sqrt(disc)) / (2 * a));
      const Eigen::Vector3d dir_G = (T_G_C.linear() * ray.normalized());
      const RayHit hit = claw_G.Cast(T_G_C.translation().cast<float>(), dir_G.cast<float>());
      if (hit.hit()) z = std::min(z, hit.t / std::sqrt(a));  // t along the unit ray
      f.depth_m[v * K.width + u] = static_cast<float>(z);
    }
  }
  return f;
}

inline GripperState State(int64_t utime) {
  GripperState s;
  s.utime = utime;
  s.T_C_G = T_C_G_at(utime * 1e-6);
  s.opening_m = kOpeningM;
  return s;
}

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    raycaster_.AddMesh(Claw().Posed(kOpeningM));
    raycaster_.Commit();
  }
  // Feeds 100 Hz states (offset 3.7 ms) and 30 Hz frames in time order;
  // `after_call` (may be empty) runs after each call to the pipeline.
  void Feed(Pipeline* p, int num_frames, const CameraIntrinsics& K = CameraIntrinsics{},
            const std::function<void()>& after_call = {}) {
    auto after = [&] {
      if (after_call) after_call();
    };
    int64_t next_state = 3700;
    for (int i = 0; i < num_frames; ++i) {
      const int64_t t = 100000 + i * 33333;
      while (next_state <= t) {
        p->AddGripperState(State(next_state));
        after();
        next_state += 10000;
      }
      p->AddDepthFrame(Render(raycaster_, T_C_G_at(t * 1e-6), t, K));
      after();
    }
    p->AddGripperState(State(next_state));
    after();
    p->Flush();
    after();
  }
  Raycaster raycaster_;
};

}  // namespace graspfill
