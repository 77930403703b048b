// SPDX-License-Identifier: BSD-3-Clause
// BuildPlannerMesh on noisy clouds sampled from known shapes, where each
// promise could fail: the dense mesh has ~10x the cap and leaves points
// outside it (so holding the points and decimating both have work to
// do), sharp edges (the cuboid) and a thin handle (the mug). Checked with
// the test's own measures: Open3D's watertight test, the triangle cap,
// and every cloud point inside the mesh (generalized winding number, and
// brute-force point-triangle distance for any that is not).
#include "graspfill/mesh/planner_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "farthest_outside.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "open3d_watertight.hpp"
#include "synth/shapes.hpp"

namespace graspfill::mesh {
namespace {

// `count` points on `shape`, each moved along its normal by a uniform
// -noise..+noise: half of them outside any mesh through their middle.
ObjectCloud NoisyCloud(synth::Shape shape, const Eigen::Vector3d& size_m, int count, double noise_m) {
  const mesh::SurfaceSamples s = mesh::SampleSurface(synth::MakeShape(shape, size_m), count, 5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> offset(static_cast<float>(-noise_m), static_cast<float>(noise_m));
  ObjectCloud cloud;
  for (size_t i = 0; i < s.points.size(); ++i) {
    cloud.points_G.push_back(s.points[i] + offset(rng) * s.normals[i]);
  }
  cloud.normals_G = s.normals;
  return cloud;
}

struct Case {
  std::string name;
  synth::Shape shape;
  Eigen::Vector3d size_m;
  int points;
};

class PlannerMeshShapes : public ::testing::TestWithParam<Case> {};

TEST_P(PlannerMeshShapes, WatertightUnderTheCapAndHoldingTheCloud) {
  const Case& c = GetParam();
  const ObjectCloud cloud = NoisyCloud(c.shape, c.size_m, c.points, 0.0008);
  PlannerMeshConfig config;
  config.max_triangles = 1500;
  const PlannerMesh p = BuildPlannerMesh(cloud, config);

  // The case is hard: the dense mesh is far over the cap and leaves the
  // noisy cloud's points up to the noise outside.
  const TriangleMesh dense = BuildCollisionMesh(cloud, config.dense);
  ASSERT_GT(dense.triangles.size(), 5u * 1500u);
  EXPECT_GT(testing::FarthestOutside(dense, cloud.points_G, 20), 0.0004);

  // The shape itself, decimated, not a fallback.
  EXPECT_EQ(p.kind, CollisionMeshKind::kDecimated) << p.fallback_reason;
  EXPECT_EQ(p.method, PlannerMeshMethod::kDecimated) << p.fallback_reason;
  EXPECT_TRUE(p.fallback_reason.empty()) << p.fallback_reason;
  EXPECT_LE(p.mesh.triangles.size(), 1500u);
  EXPECT_GT(p.mesh.triangles.size(), 100u);  // a shape, not a token
  EXPECT_TRUE(p.watertight);
  EXPECT_TRUE(testing::Open3dWatertight(p.mesh));
  EXPECT_TRUE(mesh::IsClosedOriented(p.mesh));
  EXPECT_GT(mesh::SignedVolume(p.mesh), 0.0);  // facing outwards
  // Containment: every point inside (float rounding aside), as stated
  // and by the test's own measure.
  EXPECT_LT(p.outside.max_m, 1e-6);
  EXPECT_LT(testing::FarthestOutside(p.mesh, cloud.points_G), 1e-6);
  // Not bloated: its volume at most 10% over the mesh holding the points
  // (decimation's share; the hold's own is the noise, 8-11% here), and
  // at most 20% over the shape's.
  CollisionMeshConfig holding = config.dense;
  holding.hold_points = true;
  const double held = mesh::SignedVolume(BuildCollisionMesh(cloud, holding));
  const double volume = mesh::SignedVolume(dense);
  EXPECT_LT(mesh::SignedVolume(p.mesh), 1.1 * held);
  EXPECT_LT(mesh::SignedVolume(p.mesh), 1.2 * volume);
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, PlannerMeshShapes,
    ::testing::Values(Case{"sphere", synth::Shape::kSphere, Eigen::Vector3d::Constant(0.06), 12000},
                      Case{"cuboid", synth::Shape::kCuboid, Eigen::Vector3d(0.05, 0.04, 0.08), 15000},
                      Case{"mug", synth::Shape::kMug, Eigen::Vector3d(0.11, 0.08, 0.1), 30000}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

TEST(PlannerMesh, ConvexHullHoldsEveryPointAndIsConvex) {
  const ObjectCloud cloud = NoisyCloud(synth::Shape::kMug, Eigen::Vector3d(0.11, 0.08, 0.1), 20000, 0.0005);
  PlannerMeshConfig config;
  config.convex_hull = true;
  const PlannerMesh p = BuildPlannerMesh(cloud, config);
  EXPECT_EQ(p.kind, CollisionMeshKind::kConvexHull);
  EXPECT_EQ(p.method, PlannerMeshMethod::kConvexHull);
  EXPECT_LE(p.mesh.triangles.size(), 5000u);
  EXPECT_TRUE(testing::Open3dWatertight(p.mesh));
  EXPECT_TRUE(mesh::IsClosedOriented(p.mesh));
  EXPECT_LT(p.outside.max_m, 1e-6);
  EXPECT_LT(testing::FarthestOutside(p.mesh, cloud.points_G), 1e-6);
  // Convex and facing outwards: every vertex behind every face's plane.
  for (const Eigen::Vector3i& t : p.mesh.triangles) {
    const Eigen::Vector3d a = p.mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d n = (p.mesh.vertices[t[1]].cast<double>() - a)
                                  .cross(p.mesh.vertices[t[2]].cast<double>() - a)
                                  .normalized();
    for (const Eigen::Vector3f& v : p.mesh.vertices) ASSERT_LT(n.dot(v.cast<double>() - a), 1e-6);
  }
}

TEST(PlannerMesh, ConvexHullOverTheCapIsTheDecimatedMeshsHull) {
  const ObjectCloud cloud = NoisyCloud(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.06), 12000, 0.0005);
  PlannerMeshConfig config;
  config.convex_hull = true;
  config.max_triangles = 200;  // the cloud's hull has thousands
  const PlannerMesh p = BuildPlannerMesh(cloud, config);
  EXPECT_EQ(p.kind, CollisionMeshKind::kConvexHull);
  EXPECT_LE(p.mesh.triangles.size(), 200u);
  EXPECT_TRUE(testing::Open3dWatertight(p.mesh));
  EXPECT_FALSE(p.fallback_reason.empty());
  EXPECT_LT(p.outside.max_m, 1e-6);
  EXPECT_LT(testing::FarthestOutside(p.mesh, cloud.points_G), 1e-6);
}

TEST(PlannerMesh, SameCloudSameMesh) {
  const ObjectCloud cloud = NoisyCloud(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.05), 8000, 0.0005);
  PlannerMeshConfig config;
  config.max_triangles = 800;
  const PlannerMesh a = BuildPlannerMesh(cloud, config);
  const PlannerMesh b = BuildPlannerMesh(cloud, config);
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.outside.max_m, b.outside.max_m);
}

TEST(PlannerMesh, BadConfigAndTinyCloudsAreRefused) {
  const ObjectCloud cloud = NoisyCloud(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.05), 2000, 0.0);
  PlannerMeshConfig config;
  config.max_triangles = kMinPlannerTriangles - 1;
  EXPECT_THROW(BuildPlannerMesh(cloud, config), std::invalid_argument);
  config = PlannerMeshConfig{};
  config.dense.cell_m = 0.1;
  EXPECT_THROW(BuildPlannerMesh(cloud, config), std::invalid_argument);
  ObjectCloud three;
  three.points_G = {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, 0}};
  EXPECT_THROW(BuildPlannerMesh(three, PlannerMeshConfig{}), std::invalid_argument);
  PlannerMeshConfig hull;
  hull.convex_hull = true;
  EXPECT_THROW(BuildPlannerMesh(three, hull), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::mesh
