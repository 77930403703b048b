// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/view/cloud_render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "graspfill/core/provenance_colors.hpp"

namespace graspfill::view {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The framing sphere's diameter as a share of the view's edge (a margin).
constexpr double kFill = 0.92;
// The darkest shade of a colour: a point edge-on to the view (normals),
// or at the far side of the framing sphere (no normals).
constexpr double kMinShade = 0.45;
constexpr double kMinDepthShade = 0.6;

// Disc radius [pixels]: points about their spacing apart on the picture
// should touch, so that a surface reads as a surface. The spacing is that
// of n points spread over the cloud's bounding-box surface.
int DiscRadiusPx(const ObjectCloud& cloud, double px_per_m) {
  Eigen::AlignedBox3f box;
  size_t n = 0;
  for (const Eigen::Vector3f& p : cloud.points_G) {
    if (!p.allFinite()) continue;
    box.extend(p);
    ++n;
  }
  if (n == 0) return 1;
  const Eigen::Vector3d size = box.sizes().cast<double>();
  const double area = 2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  const double spacing_m = std::sqrt(area / static_cast<double>(n));
  return std::clamp(static_cast<int>(std::lround(0.6 * spacing_m * px_per_m)), 1, 8);
}

}  // namespace

Framing FrameClouds(const std::vector<const ObjectCloud*>& clouds) {
  Eigen::AlignedBox3d box;
  for (const ObjectCloud* cloud : clouds) {
    for (const Eigen::Vector3f& p : cloud->points_G) {
      if (p.allFinite()) box.extend(p.cast<double>());
    }
  }
  Framing framing;
  if (box.isEmpty()) return framing;
  framing.center_G = box.center();
  // A single point (or a tiny cloud) still gets a picture of sensible scale.
  framing.radius_m = std::max(0.5 * box.diagonal().norm(), 1e-3);
  return framing;
}

void RenderView(const ObjectCloud& cloud, const Framing& framing, const ViewAngle& angle,
                int x0, int y0, int size_px, RgbImage* image) {
  const double az = angle.azimuth_deg * kPi / 180.0;
  const double el = angle.elevation_deg * kPi / 180.0;
  // The palm side (-z in G) is up: the camera rises towards it.
  const Eigen::Vector3d to_camera(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                  -std::sin(el));
  const Eigen::Vector3d forward = -to_camera;
  const Eigen::Vector3d minus_z(0.0, 0.0, -1.0);
  const Eigen::Vector3d up = (minus_z - minus_z.dot(forward) * forward).normalized();
  const Eigen::Vector3d right = forward.cross(up);
  const double px_per_m = kFill * 0.5 * size_px / framing.radius_m;
  const int radius = DiscRadiusPx(cloud, px_per_m);
  const bool shaded = cloud.normals_G.size() == cloud.size();
  const bool has_provenance = cloud.provenance.size() == cloud.size();

  std::vector<float> depth(static_cast<size_t>(size_px) * size_px,
                           std::numeric_limits<float>::infinity());
  const double half = 0.5 * size_px;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& point = cloud.points_G[i];
    if (!point.allFinite()) continue;
    const Eigen::Vector3d d = point.cast<double>() - framing.center_G;
    const double u = half + d.dot(right) * px_per_m;
    const double v = half - d.dot(up) * px_per_m;
    // Outside the view (a framing that does not hold the cloud): skipped
    // before the conversion to int could overflow.
    if (!(std::abs(u - half) < half + radius + 1 && std::abs(v - half) < half + radius + 1)) continue;
    const auto z = static_cast<float>(d.dot(forward));
    const Provenance p = has_provenance ? cloud.provenance[i] : Provenance::kObserved;
    // With normals: facing the camera full colour, edge-on darker. Without:
    // nearer brighter (depth cueing). Either way the shape reads.
    double shade = 1.0;
    if (shaded && cloud.normals_G[i].allFinite()) {
      const double facing = std::abs(cloud.normals_G[i].cast<double>().dot(forward));
      shade = kMinShade + (1.0 - kMinShade) * std::min(facing, 1.0);
    } else if (!shaded) {
      const double far = std::clamp(0.5 + 0.5 * z / framing.radius_m, 0.0, 1.0);
      shade = 1.0 - (1.0 - kMinDepthShade) * far;
    }
    Rgb8 color = ProvenanceColor(p);
    for (uint8_t& c : color) c = static_cast<uint8_t>(std::lround(c * shade));
    const int cu = static_cast<int>(std::floor(u));
    const int cv = static_cast<int>(std::floor(v));
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) {
        if (dx * dx + dy * dy > radius * radius) continue;
        const int px = cu + dx;
        const int py = cv + dy;
        if (px < 0 || py < 0 || px >= size_px || py >= size_px) continue;
        float& nearest = depth[static_cast<size_t>(py) * size_px + px];
        if (!(z < nearest)) continue;
        nearest = z;
        const int ix = x0 + px;
        const int iy = y0 + py;
        if (ix < 0 || iy < 0 || ix >= image->width || iy >= image->height) continue;
        uint8_t* out = &image->rgb[(static_cast<size_t>(iy) * image->width + ix) * 3];
        out[0] = color[0];
        out[1] = color[1];
        out[2] = color[2];
      }
    }
  }
}

}  // namespace graspfill::view
