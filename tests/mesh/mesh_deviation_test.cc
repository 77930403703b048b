// SPDX-License-Identifier: BSD-3-Clause
// MeasureDeviation against analytic answers: a cloud on the mesh, and the
// same cloud pushed out along the normals by a known distance.
#include "graspfill/mesh/mesh_deviation.hpp"

#include <gtest/gtest.h>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/shapes.hpp"

namespace graspfill::mesh {
namespace {

TEST(MeshDeviation, CloudOnTheMeshAndOffItByAKnownDistance) {
  const TriangleMesh box = synth::MakeShape(synth::Shape::kCuboid, Eigen::Vector3d(0.05, 0.05, 0.1));
  const mesh::SurfaceSamples s = mesh::SampleSurface(box, 200000, 5);  // ~0.25 mm spacing
  ObjectCloud on;
  on.points_G = s.points;
  const MeshDeviation d = MeasureDeviation(box, on, 20000);
  EXPECT_EQ(d.surface_samples, 20000);
  EXPECT_LT(d.cloud_to_surface_max_m, 1e-6);  // float rounding only
  EXPECT_LT(d.surface_to_cloud_p95_m, 0.0005);

  // Pushed out by 2 mm along the faces' normals: 2 mm from the surface.
  ObjectCloud off;
  for (size_t i = 0; i < s.points.size(); ++i) off.points_G.push_back(s.points[i] + 0.002f * s.normals[i]);
  const MeshDeviation e = MeasureDeviation(box, off, 20000);
  EXPECT_NEAR(e.cloud_to_surface_p50_m, 0.002, 1e-5);
  EXPECT_NEAR(e.cloud_to_surface_max_m, 0.002, 1e-5);
  EXPECT_GT(e.surface_to_cloud_p50_m, 0.0019);
}

TEST(MeshDeviation, SameInputSameNumbers) {
  const TriangleMesh sphere = synth::MakeShape(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.04));
  ObjectCloud cloud;
  cloud.points_G = mesh::SampleSurface(sphere, 5000, 9).points;
  const MeshDeviation a = MeasureDeviation(sphere, cloud, 5000);
  const MeshDeviation b = MeasureDeviation(sphere, cloud, 5000);
  EXPECT_EQ(a.surface_to_cloud_p95_m, b.surface_to_cloud_p95_m);
  EXPECT_EQ(a.cloud_to_surface_p95_m, b.cloud_to_surface_p95_m);
}

TEST(MeshDeviation, RejectsEmptyInput) {
  const TriangleMesh sphere = synth::MakeShape(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.04));
  ObjectCloud cloud;
  EXPECT_THROW(MeasureDeviation(sphere, cloud), std::invalid_argument);
  cloud.points_G.push_back({0, 0, 0});
  EXPECT_THROW(MeasureDeviation(TriangleMesh{}, cloud), std::invalid_argument);
  EXPECT_THROW(MeasureDeviation(sphere, cloud, 0), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::mesh
