// SPDX-License-Identifier: BSD-3-Clause
// Cuts the claw out of a depth frame: a pixel is removed when the posed claw
// meshes cover it and the measured depth is on the claw or behind it
// (anything the claw hides is not the object's visible surface). The claw's
// per-pixel depth comes from Embree rays (16-ray packets, only in the pixel
// tiles the claw's triangles can cover) or, as a measured alternative, from
// a z-buffer rasterization of its triangles (the same first hit per pixel
// centre; `graspfill bench` prints both). The mask is dilated by a few
// pixels to take the mixed pixels at the claw's silhouette.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::claw {

/// How the claw's per-pixel depth is computed. All give the same first hit
/// per pixel centre (up to rays grazing an edge).
enum class ClawMaskMethod {
  kRayPackets,  ///< Embree, 16-ray packets over 4x4 pixel tiles (default)
  kRaster,      ///< z-buffer over the projected triangles (~3x faster here)
  kRays,        ///< Embree, one ray per pixel
};

struct ClawMaskConfig {
  /// A pixel whose measured depth is nearer than the claw by more than this
  /// is the object in front of the claw and is kept [m].
  double front_margin_m{0.004};
  /// Removed pixels are dilated by this many pixels (silhouette mixing).
  int dilation_px{2};
  /// Ray methods cast only in 4x4 pixel tiles that a claw triangle's
  /// projection, grown by this many pixels, may overlap (the projections
  /// are exact, so 1 px covers rounding).
  int roi_margin_px{1};
  /// kRaster falls back to kRayPackets for a frame where a claw vertex is
  /// at or behind the camera plane (it cannot be projected).
  ClawMaskMethod method{ClawMaskMethod::kRayPackets};
};

class ClawMask {
 public:
  explicit ClawMask(const ClawMaskConfig& config = {});
  ~ClawMask();
  ClawMask(const ClawMask&) = delete;
  ClawMask& operator=(const ClawMask&) = delete;

  /// Keeps this claw surface (in G) and builds and commits its Embree
  /// scene. Setup-time work: call when the claw's opening changes, not per
  /// frame. Throws std::invalid_argument on a triangle index out of range.
  void SetClaw(const TriangleMesh& claw_G);

  /// Zeroes the claw's pixels in `frame` in place, with the camera at
  /// T_C_G (gripper in camera). Returns the number of pixels it zeroed
  /// (valid depths turned to 0), or -1 if `frame` is null or its depth
  /// buffer does not match its intrinsics. Allocates nothing once buffers
  /// have the frame's size. Not thread safe (one mask per thread).
  int Apply(const Eigen::Isometry3d& T_C_G, DepthFrame* frame);

  /// Per-pixel z-depth of the claw [m] from the last Apply (0 = no claw);
  /// covers the whole image, for tests and debugging.
  const std::vector<float>& claw_depth_m() const;

  /// Rays cast by the last Apply (cost statistic; 0 when rasterized).
  int last_ray_count() const;

  const ClawMaskConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::claw
