// SPDX-License-Identifier: BSD-3-Clause
// A camera looking along +z at a square plate (0.5 m) in front of a far
// wall (1.0 m), with a "claw" block (0.3 m) covering part of the plate.
// G = C for the first frame, so pixel and point are easy to relate.
#pragma once

#include <Eigen/Geometry>
#include <stdexcept>
#include <vector>

#include "graspfill/claw/primitive_meshes.hpp"
#include "graspfill/evidence/visibility_record.hpp"

namespace graspfill::testing {

constexpr float kPlateDepth = 0.5f;
constexpr float kWallDepth = 1.0f;
constexpr float kClawDepth = 0.3f;
// The plate covers pixels [200, 440) x [140, 340); the claw [300, 340) x [200, 240).
inline bool OnPlate(int u, int v) { return u >= 200 && u < 440 && v >= 140 && v < 340; }
inline bool OnClaw(int u, int v) { return u >= 300 && u < 340 && v >= 200 && v < 240; }

inline fusion::WorkspaceBox TestBox() {
  fusion::WorkspaceBox box;
  box.min_G = Eigen::Vector3d(-0.3, -0.3, 0.2);
  box.max_G = Eigen::Vector3d(0.3, 0.3, 1.2);
  return box;
}

struct TestFrame {
  DepthFrame raw;
  std::vector<float> claw_depth;
};

inline TestFrame PlateFrame(int64_t utime = 1) {
  TestFrame f;
  f.raw.utime = utime;
  const CameraIntrinsics& K = f.raw.intrinsics;
  f.raw.depth_m.assign(static_cast<size_t>(K.width) * K.height, kWallDepth);
  f.claw_depth.assign(f.raw.depth_m.size(), 0.0f);
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const size_t i = static_cast<size_t>(v) * K.width + u;
      if (OnPlate(u, v)) f.raw.depth_m[i] = kPlateDepth;
      if (OnClaw(u, v)) f.raw.depth_m[i] = f.claw_depth[i] = kClawDepth;
    }
  }
  return f;
}

// The point at pixel (u, v) and z-depth z, in C (= G for T_C_G = I).
inline Eigen::Vector3f PointAt(double u, double v, float z) {
  const CameraIntrinsics K;
  return Eigen::Vector3f(static_cast<float>((u - K.cx) / K.fx) * z, static_cast<float>((v - K.cy) / K.fy) * z,
                         z);
}

// A record holding the plate frame as its one key frame (G = C).
inline evidence::VisibilityRecord RecordOfPlate() {
  evidence::VisibilityRecord record(evidence::VisibilityConfig{}, TestBox());
  const TestFrame f = PlateFrame();
  if (!record.Offer(f.raw, f.claw_depth, Eigen::Isometry3d::Identity())) {
    throw std::logic_error("RecordOfPlate: the first frame must become a key frame");
  }
  return record;
}

// A claw block 2 cm x 2 cm about G's z axis, from 0.4 to 0.6 m deep.
inline TriangleMesh ClawBlock() {
  TriangleMesh block = claw::BoxMesh(Eigen::Vector3d(0.02, 0.02, 0.2));
  for (Eigen::Vector3f& v : block.vertices) v.z() += 0.5f;
  return block;
}

}  // namespace graspfill::testing
