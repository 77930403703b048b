// SPDX-License-Identifier: BSD-3-Clause
// The orthographic camera and the z-buffered canvas of one view (internal
// to graspfill_view): shared by the point splatter and the triangle
// rasterizer so that a cloud and a mesh of one picture line up pixel for
// pixel.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/view/cloud_render.hpp"

namespace graspfill::view {

// The darkest shade of a colour: a surface edge-on to the view.
constexpr double kMinShade = 0.45;

struct ViewCamera {
  ViewCamera(const Framing& framing, const ViewAngle& angle, int size_px) {
    // The framing sphere's diameter as a share of the view's edge (a margin).
    constexpr double kFill = 0.92;
    const double az = angle.azimuth_deg * M_PI / 180.0;
    const double el = angle.elevation_deg * M_PI / 180.0;
    // The palm side (-z in G) is up: the camera rises towards it.
    const Eigen::Vector3d to_camera(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), -std::sin(el));
    forward = -to_camera;
    const Eigen::Vector3d minus_z(0.0, 0.0, -1.0);
    up = (minus_z - minus_z.dot(forward) * forward).normalized();
    right = forward.cross(up);
    center_G = framing.center_G;
    px_per_m = kFill * 0.5 * size_px / framing.radius_m;
    half = 0.5 * size_px;
  }

  /// (u, v): the point's position in the view [pixels, from its top-left
  /// corner]; z: its depth along the view direction [m] (smaller: nearer).
  Eigen::Vector3d Project(const Eigen::Vector3d& p_G) const {
    const Eigen::Vector3d d = p_G - center_G;
    return {half + d.dot(right) * px_per_m, half - d.dot(up) * px_per_m, d.dot(forward)};
  }

  /// The shade of a surface whose normal is `normal`: 1 facing the camera,
  /// kMinShade edge-on (either side: orientation is not trusted).
  double Facing(const Eigen::Vector3d& normal) const {
    return kMinShade + (1.0 - kMinShade) * std::min(std::abs(normal.dot(forward)), 1.0);
  }

  Eigen::Vector3d right, up, forward, center_G;
  double px_per_m{1.0};
  double half{0.0};
};

// A view's square of the picture, top-left pixel (x0, y0), with its
// z-buffer: the nearest surface drawn at a pixel wins.
class ViewCanvas {
 public:
  ViewCanvas(int x0, int y0, int size_px, RgbImage* image)
      : x0_(x0),
        y0_(y0),
        size_px_(size_px),
        image_(image),
        depth_(static_cast<size_t>(size_px) * size_px, std::numeric_limits<float>::infinity()) {}

  /// Colours view pixel (px, py), 0 <= px, py < size_px, when depth z is
  /// nearer than what it shows.
  void Plot(int px, int py, float z, const Rgb8& color) {
    float& nearest = depth_[static_cast<size_t>(py) * size_px_ + px];
    if (!(z < nearest)) return;
    nearest = z;
    const int ix = x0_ + px;
    const int iy = y0_ + py;
    if (ix < 0 || iy < 0 || ix >= image_->width || iy >= image_->height) return;
    uint8_t* out = &image_->rgb[(static_cast<size_t>(iy) * image_->width + ix) * 3];
    out[0] = color[0];
    out[1] = color[1];
    out[2] = color[2];
  }

 private:
  int x0_, y0_, size_px_;
  RgbImage* image_;
  std::vector<float> depth_;
};

inline Rgb8 Shaded(Rgb8 color, double shade) {
  for (uint8_t& c : color) c = static_cast<uint8_t>(std::lround(c * shade));
  return color;
}

}  // namespace graspfill::view
