// SPDX-License-Identifier: BSD-3-Clause
// BuildCollisionMesh on clouds sampled from known shapes: watertight by
// Open3D's own test, facing outwards, on the true surface, the same twice,
// whatever the normals; bad input rejected.
#include "graspfill/mesh/collision_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "open3d_watertight.hpp"
#include "synth/shapes.hpp"

namespace graspfill::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A cloud of `count` points on `shape`, with the true outward normals.
ObjectCloud SampledCloud(synth::Shape shape, const Eigen::Vector3d& size_m, int count) {
  const mesh::SurfaceSamples s = mesh::SampleSurface(synth::MakeShape(shape, size_m), count, 3);
  ObjectCloud cloud;
  cloud.points_G = s.points;
  cloud.normals_G = s.normals;
  cloud.provenance.assign(s.points.size(), Provenance::kObserved);
  return cloud;
}

// The sphere of radius 3 cm, ~1 mm spacing (11k points).
class SphereMesh : public ::testing::Test {
 protected:
  static constexpr double kRadius = 0.03;
  ObjectCloud cloud_ = SampledCloud(synth::Shape::kSphere, Eigen::Vector3d::Constant(2 * kRadius), 11000);
  // The sphere's centre: MakeShape puts the object's base at z = 0.
  Eigen::Vector3f centre_{0.0f, 0.0f, static_cast<float>(kRadius)};

  void ExpectOnSphere(const TriangleMesh& m) const {
    ASSERT_FALSE(m.empty());
    EXPECT_TRUE(testing::Open3dWatertight(m));
    EXPECT_TRUE(mesh::IsClosedOriented(m));
    // Outward and the sphere's volume within 3% (cells round nothing off a
    // smooth surface; the sampling's noise is well under a cell).
    const double volume = 4.0 / 3.0 * kPi * std::pow(kRadius, 3);
    EXPECT_NEAR(mesh::SignedVolume(m), volume, 0.03 * volume);
    // Every vertex within 0.4 mm of the true surface (a fifth of a cell).
    double worst = 0.0;
    for (const Eigen::Vector3f& v : m.vertices) {
      worst = std::max(worst, std::abs((v - centre_).norm() - kRadius));
    }
    EXPECT_LT(worst, 0.0004);
  }
};

TEST_F(SphereMesh, IsWatertightOutwardAndOnTheSurface) {
  ExpectOnSphere(BuildCollisionMesh(cloud_, CollisionMeshConfig{}));
}

TEST_F(SphereMesh, NormalsAreOptionalAndTheirSignDoesNotMatter) {
  ObjectCloud no_normals = cloud_;
  no_normals.normals_G.clear();
  ExpectOnSphere(BuildCollisionMesh(no_normals, CollisionMeshConfig{}));
  ObjectCloud flipped = cloud_;
  for (Eigen::Vector3f& n : flipped.normals_G) n = -n;
  ExpectOnSphere(BuildCollisionMesh(flipped, CollisionMeshConfig{}));
}

TEST_F(SphereMesh, SameCloudSameMesh) {
  const TriangleMesh a = BuildCollisionMesh(cloud_, CollisionMeshConfig{});
  const TriangleMesh b = BuildCollisionMesh(cloud_, CollisionMeshConfig{});
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) ASSERT_EQ(a.vertices[i], b.vertices[i]) << i;
  for (size_t i = 0; i < a.triangles.size(); ++i) ASSERT_EQ(a.triangles[i], b.triangles[i]) << i;
}

TEST_F(SphereMesh, AHoleInTheCloudStillGivesAClosedMesh) {
  // The cap above 80% of the height cut off: a hole 48 mm across, far
  // wider than twice the fill band, so the fill reaches the inside too; the
  // mesh is then a thin closed shell along the points, still watertight.
  ObjectCloud holey;
  for (size_t i = 0; i < cloud_.size(); ++i) {
    if (cloud_.points_G[i].z() > 1.6 * kRadius) continue;
    holey.points_G.push_back(cloud_.points_G[i]);
    holey.normals_G.push_back(cloud_.normals_G[i]);
  }
  ASSERT_LT(holey.size(), cloud_.size());
  const TriangleMesh m = BuildCollisionMesh(holey, CollisionMeshConfig{});
  EXPECT_TRUE(testing::Open3dWatertight(m));
  EXPECT_TRUE(mesh::IsClosedOriented(m));
}

TEST_F(SphereMesh, HoldingPointsTakesEveryNoisyPointInAndStaysClosed) {
  // Each point moved out or in along its normal by up to 0.8 mm: the
  // surface through their middle leaves about half outside.
  ObjectCloud noisy = cloud_;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> offset(-0.0008f, 0.0008f);
  for (size_t i = 0; i < noisy.size(); ++i) noisy.points_G[i] += offset(rng) * noisy.normals_G[i];
  auto outside = [&](const TriangleMesh& m) {
    int count = 0;
    for (size_t i = 0; i < noisy.size(); i += 10) {
      count += mesh::WindingNumber(m, noisy.points_G[i].cast<double>()) < 0.5;
    }
    return count;
  };
  const TriangleMesh plain = BuildCollisionMesh(noisy, CollisionMeshConfig{});
  EXPECT_GT(outside(plain), 100);  // of 1,100 tested

  CollisionMeshConfig hold;
  hold.hold_points = true;
  const TriangleMesh held = BuildCollisionMesh(noisy, hold);
  EXPECT_EQ(outside(held), 0);
  EXPECT_TRUE(testing::Open3dWatertight(held));
  EXPECT_TRUE(mesh::IsClosedOriented(held));
  // Bulging only where a point was left out: every vertex within the
  // noise and a cell (a node next to an outside point turns negative, and
  // the surface moves past it) of the sphere; on average out by about the
  // noise (the points' envelope), not by a cell.
  double worst = 0.0, sum = 0.0;
  for (const Eigen::Vector3f& v : held.vertices) {
    const double d = (v - centre_).norm() - kRadius;
    worst = std::max(worst, std::abs(d));
    sum += d;
  }
  const double mean = sum / static_cast<double>(held.vertices.size());
  EXPECT_LT(worst, 0.0008 + hold.cell_m);
  EXPECT_GT(mean, 0.0);
  EXPECT_LT(mean, 0.001);
}

TEST(CollisionMesh, CuboidEdgesRoundOffWithinACell) {
  const Eigen::Vector3d size(0.05, 0.04, 0.08);
  const ObjectCloud cloud = SampledCloud(synth::Shape::kCuboid, size, 20000);
  const CollisionMeshConfig config;
  const TriangleMesh m = BuildCollisionMesh(cloud, config);
  EXPECT_TRUE(testing::Open3dWatertight(m));
  // Distance of each vertex to the box's surface (x, y centred, z from 0).
  const Eigen::Vector3d half = size / 2;
  int beyond_half_cell = 0;
  double worst = 0.0;
  for (const Eigen::Vector3f& v : m.vertices) {
    const Eigen::Vector3d q(std::abs(v.x()), std::abs(v.y()), std::abs(v.z() - half.z()));
    const Eigen::Vector3d outside = (q - half).cwiseMax(0.0);
    const double d = outside.norm() > 0.0 ? outside.norm() : -(q - half).maxCoeff();
    worst = std::max(worst, d);
    beyond_half_cell += d > 0.5 * config.cell_m;
  }
  EXPECT_LT(worst, config.cell_m);
  EXPECT_LT(beyond_half_cell, 0.02 * m.vertices.size());
}

TEST(CollisionMesh, RejectsBadInput) {
  ObjectCloud three;
  three.points_G = {{0, 0, 0}, {1e-3f, 0, 0}, {0, 1e-3f, 0}};
  EXPECT_THROW(BuildCollisionMesh(three, CollisionMeshConfig{}), std::invalid_argument);

  ObjectCloud cloud = SampledCloud(synth::Shape::kSphere, Eigen::Vector3d::Constant(0.02), 500);
  ObjectCloud nan = cloud;
  nan.points_G[7].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(BuildCollisionMesh(nan, CollisionMeshConfig{}), std::invalid_argument);
  ObjectCloud short_normals = cloud;
  short_normals.normals_G.pop_back();
  EXPECT_THROW(BuildCollisionMesh(short_normals, CollisionMeshConfig{}), std::invalid_argument);

  CollisionMeshConfig bad;
  bad.cell_m = 0.0;
  try {
    BuildCollisionMesh(cloud, bad);
    FAIL() << "cell_m 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cell_m"), std::string::npos) << e.what();
  }
  // A grid too fine for the cloud's extent (1 m at 0.2 mm: 125 G nodes).
  ObjectCloud wide = cloud;
  wide.points_G.push_back({1.0f, 1.0f, 1.0f});
  wide.normals_G.push_back({0.0f, 0.0f, 1.0f});
  CollisionMeshConfig fine;
  fine.cell_m = 0.0002;
  EXPECT_THROW(BuildCollisionMesh(wide, fine), std::runtime_error);
}

}  // namespace
}  // namespace graspfill::mesh
