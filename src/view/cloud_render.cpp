// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/view/cloud_render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "graspfill/core/provenance_colors.hpp"
#include "view_camera.hpp"

namespace graspfill::view {
namespace {

// The darkest shade of a point at the far side of the framing sphere (no
// normals).
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

void RenderView(const ObjectCloud& cloud, const Framing& framing, const ViewAngle& angle, int x0, int y0,
                int size_px, RgbImage* image) {
  const ViewCamera camera(framing, angle, size_px);
  const int radius = DiscRadiusPx(cloud, camera.px_per_m);
  const bool shaded = cloud.normals_G.size() == cloud.size();
  const bool has_provenance = cloud.provenance.size() == cloud.size();

  ViewCanvas canvas(x0, y0, size_px, image);
  const double half = camera.half;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& point = cloud.points_G[i];
    if (!point.allFinite()) continue;
    const Eigen::Vector3d uvz = camera.Project(point.cast<double>());
    const double u = uvz.x();
    const double v = uvz.y();
    // Outside the view (a framing that does not hold the cloud): skipped
    // before the conversion to int could overflow.
    if (!(std::abs(u - half) < half + radius + 1 && std::abs(v - half) < half + radius + 1)) continue;
    const auto z = static_cast<float>(uvz.z());
    const Provenance p = has_provenance ? cloud.provenance[i] : Provenance::kObserved;
    // With normals: facing the camera full colour, edge-on darker. Without:
    // nearer brighter (depth cueing). Either way the shape reads.
    double shade = 1.0;
    if (shaded && cloud.normals_G[i].allFinite()) {
      shade = camera.Facing(cloud.normals_G[i].cast<double>());
    } else if (!shaded) {
      const double far = std::clamp(0.5 + 0.5 * z / framing.radius_m, 0.0, 1.0);
      shade = 1.0 - (1.0 - kMinDepthShade) * far;
    }
    const Rgb8 color = Shaded(ProvenanceColor(p), shade);
    const int cu = static_cast<int>(std::floor(u));
    const int cv = static_cast<int>(std::floor(v));
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) {
        if (dx * dx + dy * dy > radius * radius) continue;
        const int px = cu + dx;
        const int py = cv + dy;
        if (px < 0 || py < 0 || px >= size_px || py >= size_px) continue;
        canvas.Plot(px, py, z, color);
      }
    }
  }
}

}  // namespace graspfill::view
