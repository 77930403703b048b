// SPDX-License-Identifier: BSD-3-Clause
// Crops a depth frame to the object's workspace: a box in the gripper frame.
// Everything outside it (background, the robot arm behind the palm, the
// table) is zeroed, so the TSDF only ever sees the object and the claw.
#pragma once

#include <Eigen/Geometry>

#include "graspfill/types.hpp"

namespace graspfill::fusion {

/// Axis-aligned box in the gripper frame G [m]. The default holds objects up
/// to 20 x 20 x 29 cm below the palm (the palm face is z = 0, the object
/// lies along +z) and excludes the palm itself.
struct WorkspaceBox {
  Eigen::Vector3d min_G{-0.10, -0.10, 0.003};
  Eigen::Vector3d max_G{0.10, 0.10, 0.30};

  bool Contains(const Eigen::Vector3d& p_G) const {
    return (p_G.array() >= min_G.array()).all() && (p_G.array() <= max_G.array()).all();
  }
  /// Throws std::invalid_argument unless min < max on every axis.
  void Validate() const;
};

/// Pixel rectangle [u0, u1) x [v0, v1).
struct PixelRect {
  int u0{0}, v0{0}, u1{0}, v1{0};
  bool empty() const { return u1 <= u0 || v1 <= v0; }
  int area() const { return empty() ? 0 : (u1 - u0) * (v1 - v0); }
};

/// Image rectangle covering the projection of `box` seen from the camera at
/// T_C_G, grown by `margin_px` and clipped to the image; the full image if
/// part of the box is behind the camera.
PixelRect ProjectBox(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G,
                     const CameraIntrinsics& intrinsics, int margin_px = 1);

/// Zeroes every pixel of `frame` whose back-projected point is outside the
/// box. Returns the number of valid pixels kept; *roi (optional) receives
/// the rectangle outside which every pixel is now zero. Allocates nothing.
/// @throws std::invalid_argument unless the depth holds width x height
/// pixels (both overloads).
int CropToWorkspace(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, DepthFrame* frame,
                    PixelRect* roi = nullptr);
/// The same crop of `in`, written to *out (resized to `in`'s size; its
/// memory reused): one pass over the frame where a copy and a crop in place
/// take two.
int CropToWorkspace(const WorkspaceBox& box, const Eigen::Isometry3d& T_C_G, const DepthFrame& in,
                    DepthFrame* out, PixelRect* roi = nullptr);

}  // namespace graspfill::fusion
