// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/view/mesh_render.hpp"

#include <algorithm>
#include <cmath>

#include "graspfill/core/provenance_colors.hpp"
#include "view_camera.hpp"

namespace graspfill::view {
namespace {

// Twice the signed area of (a, b, p) in the view's pixel plane.
double Edge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double px, double py) {
  return (b.x() - a.x()) * (py - a.y()) - (b.y() - a.y()) * (px - a.x());
}

}  // namespace

void RenderMeshView(const TriangleMesh& mesh, const std::vector<Provenance>& vertex_provenance,
                    const Framing& framing, const ViewAngle& angle, int x0, int y0, int size_px,
                    RgbImage* image) {
  const ViewCamera camera(framing, angle, size_px);
  const bool has_provenance = vertex_provenance.size() == mesh.vertices.size();
  const auto num_vertices = static_cast<int64_t>(mesh.vertices.size());
  ViewCanvas canvas(x0, y0, size_px, image);
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    if ((tri.array() < 0).any() || (tri.cast<int64_t>().array() >= num_vertices).any()) continue;
    const Eigen::Vector3f* v[3] = {&mesh.vertices[tri[0]], &mesh.vertices[tri[1]], &mesh.vertices[tri[2]]};
    if (!v[0]->allFinite() || !v[1]->allFinite() || !v[2]->allFinite()) continue;
    const Eigen::Vector3d normal = (*v[1] - *v[0]).cast<double>().cross((*v[2] - *v[0]).cast<double>());
    if (!(normal.norm() > 0.0)) continue;  // degenerate: covers nothing
    const Eigen::Vector3d p[3] = {camera.Project(v[0]->cast<double>()), camera.Project(v[1]->cast<double>()),
                                  camera.Project(v[2]->cast<double>())};
    const double area = Edge(p[0], p[1], p[2].x(), p[2].y());
    if (area == 0.0) continue;  // edge-on to the view
    // Pixels whose centre may be inside, clipped to the view (before the
    // conversion to int could overflow).
    const double lo_u = std::max({std::min({p[0].x(), p[1].x(), p[2].x()}), 0.0});
    const double hi_u = std::min({std::max({p[0].x(), p[1].x(), p[2].x()}), double(size_px)});
    const double lo_v = std::max({std::min({p[0].y(), p[1].y(), p[2].y()}), 0.0});
    const double hi_v = std::min({std::max({p[0].y(), p[1].y(), p[2].y()}), double(size_px)});
    if (!(lo_u < hi_u && lo_v < hi_v)) continue;
    const Provenance prov = has_provenance ? vertex_provenance[tri[0]] : Provenance::kObserved;
    const Rgb8 color = Shaded(ProvenanceColor(prov), camera.Facing(normal.normalized()));
    const int u_begin = static_cast<int>(std::floor(lo_u));
    const int u_end = std::min(static_cast<int>(std::ceil(hi_u)), size_px);
    const int v_begin = static_cast<int>(std::floor(lo_v));
    const int v_end = std::min(static_cast<int>(std::ceil(hi_v)), size_px);
    for (int py = v_begin; py < v_end; ++py) {
      for (int px = u_begin; px < u_end; ++px) {
        const double cu = px + 0.5, cv = py + 0.5;
        // Barycentric weights, the same sign as the area inside.
        const double w0 = Edge(p[1], p[2], cu, cv) / area;
        const double w1 = Edge(p[2], p[0], cu, cv) / area;
        const double w2 = Edge(p[0], p[1], cu, cv) / area;
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
        canvas.Plot(px, py, static_cast<float>(w0 * p[0].z() + w1 * p[1].z() + w2 * p[2].z()), color);
      }
    }
  }
}

}  // namespace graspfill::view
