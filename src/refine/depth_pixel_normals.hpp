// SPDX-License-Identifier: BSD-3-Clause
// Points and normals of depth pixels for the ICP of the claw registration
// and the object tracker (private to src/refine): a pixel's normal is the
// cross product of its neighbours `step` pixels away left-right and
// up-down (a wider baseline than 1 px: sensor noise of ~1 mm over 1 mm
// pixels would turn it by ~45 deg), turned to face the camera.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>

#include "graspfill/types.hpp"

namespace graspfill::refine {

class DepthPixelNormals {
 public:
  // `depth` holds K.width x K.height depths [m] (0: none); a neighbour
  // farther in depth than `max_jump_m` from the pixel (a silhouette) makes
  // no normal. The caller keeps `step` pixels off the image's border.
  DepthPixelNormals(const CameraIntrinsics& K, const float* depth, int step, double max_jump_m)
      : fx_(static_cast<float>(K.fx)),
        fy_(static_cast<float>(K.fy)),
        cx_(static_cast<float>(K.cx)),
        cy_(static_cast<float>(K.cy)),
        depth_(depth),
        width_(K.width),
        step_(step),
        jump_(static_cast<float>(max_jump_m)) {}

  // The frame has a size and one depth per pixel.
  static bool Fits(const DepthFrame& frame) {
    const CameraIntrinsics& K = frame.intrinsics;
    return K.width > 0 && K.height > 0 && frame.depth_m.size() == static_cast<size_t>(K.width) * K.height;
  }

  // Pixel (u, v) at depth z, in C.
  Eigen::Vector3f Point(int u, int v, float z) const {
    return Eigen::Vector3f((u - cx_) / fx_ * z, (v - cy_) / fy_ * z, z);
  }

  // The unit normal of pixel (u, v) (depth z > 0, point p_C), facing the
  // camera; false where its neighbours make none.
  bool Normal(int u, int v, float z, const Eigen::Vector3f& p_C, Eigen::Vector3f* n) const {
    const int W = width_, step = step_;
    const float zl = depth_[v * W + u - step], zr = depth_[v * W + u + step];
    const float zu = depth_[(v - step) * W + u], zd = depth_[(v + step) * W + u];
    if (!(zl > 0.0f && zr > 0.0f && zu > 0.0f && zd > 0.0f)) return false;
    if (std::abs(zl - z) > jump_ || std::abs(zr - z) > jump_ || std::abs(zu - z) > jump_ ||
        std::abs(zd - z) > jump_) {
      return false;
    }
    *n = (Point(u + step, v, zr) - Point(u - step, v, zl))
             .cross(Point(u, v + step, zd) - Point(u, v - step, zu));
    const float len = n->norm();
    if (!(len > 0.0f)) return false;
    *n /= len;
    if (n->dot(p_C) > 0.0f) *n = -*n;
    return true;
  }

 private:
  float fx_, fy_, cx_, cy_;
  const float* depth_;
  int width_;
  int step_;
  float jump_;
};

}  // namespace graspfill::refine
