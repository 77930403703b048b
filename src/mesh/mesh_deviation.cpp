// SPDX-License-Identifier: BSD-3-Clause
// Mesh-to-cloud and cloud-to-mesh distances: nearest points through
// NearestDistances (a KD-tree), closest surface points through Open3D's
// RaycastingScene (Embree's point queries), inside or not by counting
// crossings along rays (graspfill's Raycaster, Embree too).
#include "graspfill/mesh/mesh_deviation.hpp"

#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/RaycastingScene.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "graspfill/core/percentile.hpp"
#include "graspfill/core/raycaster.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/nearest_distances.hpp"

namespace graspfill::mesh {
namespace {

constexpr uint64_t kSampleSeed = 1;
// OutsideDistances' rays: past each hit by this much [m]; at most this many
// crossings counted (a closed object mesh has a handful).
constexpr float kCrossingStepM = 1e-6f;
constexpr int kMaxCrossings = 1000;

namespace core = open3d::core;

core::Tensor PointsTensor(const std::vector<Eigen::Vector3f>& points) {
  std::vector<float> xyz;
  xyz.reserve(3 * points.size());
  for (const Eigen::Vector3f& p : points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  return core::Tensor(xyz, {static_cast<int64_t>(points.size()), 3}, core::Float32);
}

// The mesh as Embree's scene (Open3D's RaycastingScene).
void AddMesh(const TriangleMesh& mesh, open3d::t::geometry::RaycastingScene* scene) {
  std::vector<uint32_t> triangles;
  triangles.reserve(3 * mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    triangles.insert(triangles.end(), {static_cast<uint32_t>(t.x()), static_cast<uint32_t>(t.y()),
                                       static_cast<uint32_t>(t.z())});
  }
  scene->AddTriangles(
      PointsTensor(mesh.vertices),
      core::Tensor(triangles, {static_cast<int64_t>(mesh.triangles.size()), 3}, core::UInt32));
}

// Distance of each point to the closest point of the mesh's surface [m].
std::vector<double> SurfaceDistances(const TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& points,
                                     int threads) {
  open3d::t::geometry::RaycastingScene scene;
  AddMesh(mesh, &scene);
  const core::Tensor d = scene.ComputeDistance(PointsTensor(points), threads).Contiguous();
  const float* data = d.GetDataPtr<float>();
  return std::vector<double>(data, data + points.size());
}

}  // namespace

MeshDeviation MeasureDeviation(const TriangleMesh& mesh, const ObjectCloud& cloud, int surface_samples) {
  if (mesh.empty()) throw std::invalid_argument("mesh deviation: the mesh has no triangles");
  if (cloud.size() == 0) throw std::invalid_argument("mesh deviation: the cloud has no points");
  if (surface_samples < 1) throw std::invalid_argument("mesh deviation: surface_samples < 1");
  const SurfaceSamples samples = SampleSurface(mesh, surface_samples, kSampleSeed);
  if (samples.points.empty()) throw std::invalid_argument("mesh deviation: the mesh has zero area");

  MeshDeviation d;
  d.surface_samples = static_cast<int>(samples.points.size());
  const std::vector<double> out = NearestDistances(samples.points, cloud.points_G);
  d.surface_to_cloud_p50_m = Percentile(out, 50.0);
  d.surface_to_cloud_p95_m = Percentile(out, 95.0);
  d.surface_to_cloud_max_m = Percentile(out, 100.0);
  const std::vector<double> in = SurfaceDistances(mesh, cloud.points_G, 0);
  d.cloud_to_surface_p50_m = Percentile(in, 50.0);
  d.cloud_to_surface_p95_m = Percentile(in, 95.0);
  d.cloud_to_surface_max_m = Percentile(in, 100.0);
  return d;
}

std::vector<double> OutsideDistances(const TriangleMesh& closed_mesh,
                                     const std::vector<Eigen::Vector3f>& points,
                                     std::vector<int>* closest_triangle) {
  if (closed_mesh.empty()) throw std::invalid_argument("outside distances: the mesh has no triangles");
  if (points.empty()) return {};
  // Skewed directions, none along an axis: a grid-made mesh's edges and
  // faces lie along the axes, where a ray would run along them.
  static const std::array<Eigen::Vector3f, 3> kRays{
      Eigen::Vector3f(0.5377f, 0.8119f, 0.2275f).normalized(),
      Eigen::Vector3f(-0.6913f, 0.1536f, 0.7061f).normalized(),
      Eigen::Vector3f(0.2061f, -0.7739f, -0.5988f).normalized()};
  // Embree through graspfill's Raycaster: Open3D 0.16's ray casts find no
  // hits here (its distance queries do).
  Raycaster raycaster;
  raycaster.AddMesh(closed_mesh);
  raycaster.Commit();
  open3d::t::geometry::RaycastingScene scene;
  AddMesh(closed_mesh, &scene);
  std::vector<int> odd(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i) {
    for (const Eigen::Vector3f& direction : kRays) {
      // Crossings, one cast each: past each hit by a micrometre, so that an
      // edge shared by two triangles counts once.
      int crossings = 0;
      for (RayHit hit = raycaster.Cast(points[i], direction); hit.hit() && crossings < kMaxCrossings;
           hit = raycaster.Cast(points[i], direction, hit.t + kCrossingStepM)) {
        ++crossings;
      }
      odd[i] += crossings & 1;
    }
  }
  const core::Tensor query = PointsTensor(points);
  auto closest = scene.ComputeClosestPoints(query, 1);
  const core::Tensor surface = closest["points"].Contiguous();
  const core::Tensor triangle = closest["primitive_ids"].Contiguous();
  const float* xyz = surface.GetDataPtr<float>();
  const uint32_t* id = triangle.GetDataPtr<uint32_t>();
  std::vector<double> d(points.size(), 0.0);
  if (closest_triangle != nullptr) closest_triangle->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (closest_triangle != nullptr) (*closest_triangle)[i] = static_cast<int>(id[i]);
    if (odd[i] >= 2) continue;  // inside
    d[i] = (points[i] - Eigen::Vector3f(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2])).norm();
  }
  return d;
}

OutsideDeviation SummarizeOutside(const std::vector<double>& outside_m) {
  OutsideDeviation o;
  if (outside_m.empty()) return o;
  o.max_m = Percentile(outside_m, 100.0);
  o.p99_m = Percentile(outside_m, 99.0);
  for (const double d : outside_m) o.points_outside += d > 0.0;
  return o;
}

}  // namespace graspfill::mesh
