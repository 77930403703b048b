// SPDX-License-Identifier: BSD-3-Clause
// The planner's mesh: the dense mesh holding every point, decimated
// outwards to the cap (the header says why that keeps both promises); or a
// convex hull (qhull through Open3D).
#include "graspfill/mesh/planner_mesh.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "outward_decimation.hpp"

namespace graspfill::mesh {
namespace {

// CollisionMeshConfig::Validate's largest cell [m].
constexpr double kMaxCellM = 0.02;
// Triangles fall as 1 / cell^2; cells a little coarser than the shortfall
// says, so that one more try usually reaches the cap.
constexpr double kCoarsenMargin = 1.1;

open3d::geometry::TriangleMesh ToOpen3d(const TriangleMesh& m) {
  open3d::geometry::TriangleMesh o;
  o.vertices_.reserve(m.vertices.size());
  for (const Eigen::Vector3f& v : m.vertices) o.vertices_.push_back(v.cast<double>());
  o.triangles_ = m.triangles;
  return o;
}

TriangleMesh FromOpen3d(const open3d::geometry::TriangleMesh& o) {
  TriangleMesh m;
  m.vertices.reserve(o.vertices_.size());
  for (const Eigen::Vector3d& v : o.vertices_) m.vertices.push_back(v.cast<float>());
  m.triangles = o.triangles_;
  return m;
}

// The convex hull of `points` with outward triangles; empty when qhull
// cannot make one (all points on a plane).
TriangleMesh ConvexHull(const std::vector<Eigen::Vector3f>& points) {
  open3d::geometry::PointCloud pc;
  pc.points_.reserve(points.size());
  for (const Eigen::Vector3f& p : points) pc.points_.push_back(p.cast<double>());
  TriangleMesh hull;
  try {
    hull = FromOpen3d(*std::get<0>(pc.ComputeConvexHull()));
  } catch (const std::exception&) {
    return {};  // qhull's error: a flat or degenerate set
  }
  if (SignedVolume(hull) < 0.0) {  // qhull's triangles come either way
    for (Eigen::Vector3i& t : hull.triangles) std::swap(t[1], t[2]);
  }
  return hull;
}

// Watertightness and the points outside, measured on the result.
PlannerMesh Measured(TriangleMesh mesh, const ObjectCloud& cloud, CollisionMeshKind kind,
                     PlannerMeshMethod method) {
  PlannerMesh p;
  p.kind = kind;
  p.method = method;
  p.watertight = IsWatertight(mesh);
  p.outside = SummarizeOutside(OutsideDistances(mesh, cloud.points_G));
  p.mesh = std::move(mesh);
  return p;
}

// The hull of `points`, within the cap, measured against the cloud.
PlannerMesh HullOf(const std::vector<Eigen::Vector3f>& points, const ObjectCloud& cloud,
                   const PlannerMeshConfig& config) {
  TriangleMesh hull = ConvexHull(points);
  if (hull.empty()) {
    throw std::runtime_error("planner mesh: no convex hull of the cloud (are its points on a plane?)");
  }
  if (static_cast<int64_t>(hull.triangles.size()) > config.max_triangles) {
    throw std::runtime_error("planner mesh: the convex hull has " + std::to_string(hull.triangles.size()) +
                             " triangles, over the cap of " + std::to_string(config.max_triangles));
  }
  return Measured(std::move(hull), cloud, CollisionMeshKind::kConvexHull, PlannerMeshMethod::kConvexHull);
}

std::string Millimetres(double m) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g mm", m * 1e3);
  return text;
}

// The decimated shape, or the cloud's hull where no cells make one within
// the cap (fallback_reason says why).
PlannerMesh BuildDecimated(const ObjectCloud& cloud, const PlannerMeshConfig& config) {
  CollisionMeshConfig grid = config.dense;
  grid.hold_points = true;
  TriangleMesh dense = BuildCollisionMesh(cloud, grid);
  const int64_t dense_triangles = static_cast<int64_t>(dense.triangles.size());
  std::string reason;
  for (;;) {
    if (static_cast<int64_t>(dense.triangles.size()) <= config.max_triangles) {
      PlannerMesh p =
          Measured(std::move(dense), cloud, CollisionMeshKind::kDecimated, PlannerMeshMethod::kDense);
      p.cell_m = grid.cell_m;
      p.dense_triangles = dense_triangles;
      p.fallback_reason = reason;
      return p;
    }
    OutwardDecimation d = DecimateOutward(dense, config.max_triangles);
    if (d.reached_budget) {
      PlannerMesh p =
          Measured(std::move(d.mesh), cloud, CollisionMeshKind::kDecimated, PlannerMeshMethod::kDecimated);
      p.cell_m = grid.cell_m;
      p.dense_triangles = dense_triangles;
      p.fallback_reason = reason;
      return p;
    }
    // Every collapse left would fold or cross: fewer, larger cells to
    // start from.
    reason += std::string(reason.empty() ? "" : "; ") + "decimation stopped at " +
              std::to_string(d.mesh.triangles.size()) + " triangles on " + Millimetres(grid.cell_m) +
              " cells";
    if (grid.cell_m >= kMaxCellM) break;
    const double shortfall = static_cast<double>(d.mesh.triangles.size()) / config.max_triangles;
    grid.cell_m = std::min(kMaxCellM, grid.cell_m * std::sqrt(shortfall) * kCoarsenMargin);
    dense = BuildCollisionMesh(cloud, grid);
  }
  PlannerMesh hull = HullOf(cloud.points_G, cloud, config);
  hull.dense_triangles = dense_triangles;
  hull.fallback_reason = reason + "; the convex hull instead";
  return hull;
}

}  // namespace

const char* PlannerMeshMethodName(PlannerMeshMethod method) {
  switch (method) {
    case PlannerMeshMethod::kDense:
      return "dense";
    case PlannerMeshMethod::kDecimated:
      return "decimated";
    case PlannerMeshMethod::kConvexHull:
      return "convex_hull";
  }
  return "unknown";
}

void PlannerMeshConfig::Validate() const {
  if (max_triangles < kMinPlannerTriangles || max_triangles > kMaxPlannerTriangles) {
    throw std::invalid_argument(
        "PlannerMeshConfig: max_triangles must be in " + std::to_string(kMinPlannerTriangles) + ".." +
        std::to_string(kMaxPlannerTriangles) + ", not " + std::to_string(max_triangles));
  }
  dense.Validate();
}

bool IsWatertight(const TriangleMesh& mesh) { return ToOpen3d(mesh).IsWatertight(); }

PlannerMesh BuildPlannerMesh(const ObjectCloud& cloud, const PlannerMeshConfig& config) {
  config.Validate();
  if (!config.convex_hull) return BuildDecimated(cloud, config);
  if (cloud.size() < 4) {
    throw std::invalid_argument("planner mesh: the cloud has " + std::to_string(cloud.size()) +
                                " points; at least 4 are needed");
  }
  if (static_cast<int64_t>(ConvexHull(cloud.points_G).triangles.size()) <= config.max_triangles) {
    return HullOf(cloud.points_G, cloud, config);
  }
  // Too many for the cap: the hull of the decimated mesh's vertices (a
  // closed mesh of V vertices has 2V - 4 triangles, so its hull has no
  // more).
  const PlannerMesh shape = BuildDecimated(cloud, config);
  PlannerMesh hull = HullOf(shape.mesh.vertices, cloud, config);
  hull.cell_m = shape.cell_m;
  hull.dense_triangles = shape.dense_triangles;
  hull.fallback_reason = "the cloud's hull is over the cap: the hull of the decimated mesh";
  return hull;
}

}  // namespace graspfill::mesh
