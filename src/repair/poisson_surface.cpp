// SPDX-License-Identifier: BSD-3-Clause
#include "poisson_surface.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace graspfill::repair::fill {

PoissonSurface ReconstructPoisson(const PointList& points, const std::vector<int>& subset,
                                  const std::vector<Eigen::Vector3f>& normals, int depth, double scale) {
  open3d::geometry::PointCloud pcd;
  pcd.points_.reserve(subset.size());
  pcd.normals_.reserve(subset.size());
  Box extent;
  extent.setEmpty();
  for (size_t i = 0; i < subset.size(); ++i) {
    pcd.points_.push_back(points[subset[i]].cast<double>());
    pcd.normals_.push_back(normals[i].cast<double>());
    extent.extend(points[subset[i]]);
  }
  PoissonSurface out;
  out.cell_m = subset.empty() ? 0.0 : scale * extent.sizes().maxCoeff() / std::ldexp(1.0, depth);
  // One thread: the repair runs single-threaded and stays deterministic.
  std::tie(out.mesh, out.densities) = open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(
      pcd, static_cast<size_t>(depth), 0.0f, static_cast<float>(scale), false, 1);
  return out;
}

void SampleMesh(const open3d::geometry::TriangleMesh& mesh, const HoleFrame& frame, const FillRegion& region,
                bool check_facing, double cos_max_angle, const std::vector<bool>* keep_vertex, double density,
                Rng* rng, GapTest* gap, PointList* out) {
  std::vector<int> tris;
  std::vector<double> cumulative;
  double total = 0.0;
  const Eigen::AlignedBox3d region_box(region.lo, region.hi);
  for (size_t t = 0; t < mesh.triangles_.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles_[t];
    if (keep_vertex != nullptr &&
        !((*keep_vertex)[tri(0)] && (*keep_vertex)[tri(1)] && (*keep_vertex)[tri(2)])) {
      continue;
    }
    const Eigen::Vector3d& a = mesh.vertices_[tri(0)];
    const Eigen::Vector3d& b = mesh.vertices_[tri(1)];
    const Eigen::Vector3d& c = mesh.vertices_[tri(2)];
    Eigen::AlignedBox3d local(frame.Local(a));
    local.extend(frame.Local(b));
    local.extend(frame.Local(c));
    if (!local.intersects(region_box)) continue;
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area2 = cross.norm();
    if (area2 <= 0.0) continue;
    if (check_facing && cross.dot(frame.n) < cos_max_angle * area2) continue;
    total += 0.5 * area2;
    tris.push_back(static_cast<int>(t));
    cumulative.push_back(total);
  }
  if (tris.empty()) return;
  const double expected = std::min(total * density, 5e6);
  // Stochastic rounding keeps the expected count exact for small patches.
  auto count = static_cast<long>(expected);
  if (rng->Uniform() < expected - static_cast<double>(count)) ++count;
  for (long i = 0; i < count; ++i) {
    const double pick = rng->Uniform() * total;
    const size_t k = std::min<size_t>(
        tris.size() - 1, static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                             cumulative.begin()));
    const Eigen::Vector3i& tri = mesh.triangles_[tris[k]];
    const double r1 = std::sqrt(rng->Uniform()), r2 = rng->Uniform();
    const Eigen::Vector3d p = (1.0 - r1) * mesh.vertices_[tri(0)] + r1 * (1.0 - r2) * mesh.vertices_[tri(1)] +
                              r1 * r2 * mesh.vertices_[tri(2)];
    if (!region.Contains(frame.Local(p)) || !region.InZ(p.z())) continue;
    const Eigen::Vector3f pf = p.cast<float>();
    if (gap->IsNew(pf)) out->push_back(pf);
  }
}

}  // namespace graspfill::repair::fill
