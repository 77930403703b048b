// SPDX-License-Identifier: BSD-3-Clause
// Mesh-to-cloud and cloud-to-mesh distances: nearest points through
// eval::NearestDistances (KD-tree), closest surface points through Open3D's
// RaycastingScene (Embree's point queries).
#include "graspfill/mesh/mesh_deviation.hpp"

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

#include <stdexcept>
#include <vector>

#include "graspfill/eval/metrics.hpp"
#include "graspfill/synth/mesh_sampling.hpp"

namespace graspfill::mesh {
namespace {

constexpr uint64_t kSampleSeed = 1;

// Distance of each point to the closest point of the mesh's surface [m].
std::vector<double> SurfaceDistances(const TriangleMesh& mesh,
                                     const std::vector<Eigen::Vector3f>& points) {
  namespace core = open3d::core;
  std::vector<float> vertices, queries;
  std::vector<uint32_t> triangles;
  for (const Eigen::Vector3f& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
  for (const Eigen::Vector3i& t : mesh.triangles) {
    triangles.insert(triangles.end(), {static_cast<uint32_t>(t.x()), static_cast<uint32_t>(t.y()),
                                       static_cast<uint32_t>(t.z())});
  }
  for (const Eigen::Vector3f& p : points) queries.insert(queries.end(), {p.x(), p.y(), p.z()});
  const auto rows = [](const auto& v) { return static_cast<int64_t>(v.size() / 3); };
  open3d::t::geometry::RaycastingScene scene;
  scene.AddTriangles(core::Tensor(vertices, {rows(vertices), 3}, core::Float32),
                     core::Tensor(triangles, {rows(triangles), 3}, core::UInt32));
  const core::Tensor d =
      scene.ComputeDistance(core::Tensor(queries, {rows(queries), 3}, core::Float32)).Contiguous();
  const float* data = d.GetDataPtr<float>();
  return std::vector<double>(data, data + points.size());
}

}  // namespace

MeshDeviation MeasureDeviation(const TriangleMesh& mesh, const ObjectCloud& cloud,
                               int surface_samples) {
  if (mesh.empty()) throw std::invalid_argument("mesh deviation: the mesh has no triangles");
  if (cloud.size() == 0) throw std::invalid_argument("mesh deviation: the cloud has no points");
  if (surface_samples < 1) throw std::invalid_argument("mesh deviation: surface_samples < 1");
  const synth::SurfaceSamples samples = synth::SampleSurface(mesh, surface_samples, kSampleSeed);
  if (samples.points.empty()) throw std::invalid_argument("mesh deviation: the mesh has zero area");

  MeshDeviation d;
  d.surface_samples = static_cast<int>(samples.points.size());
  const std::vector<double> out = eval::NearestDistances(samples.points, cloud.points_G);
  d.surface_to_cloud_p50_m = eval::Percentile(out, 50.0);
  d.surface_to_cloud_p95_m = eval::Percentile(out, 95.0);
  d.surface_to_cloud_max_m = eval::Percentile(out, 100.0);
  const std::vector<double> in = SurfaceDistances(mesh, cloud.points_G);
  d.cloud_to_surface_p50_m = eval::Percentile(in, 50.0);
  d.cloud_to_surface_p95_m = eval::Percentile(in, 95.0);
  d.cloud_to_surface_max_m = eval::Percentile(in, 100.0);
  return d;
}

}  // namespace graspfill::mesh
