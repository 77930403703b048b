// SPDX-License-Identifier: BSD-3-Clause
// The triangle-mesh measurements on a cuboid, whose area, volume and
// closest points follow from its size.
#include "graspfill/mesh/mesh_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "synth/shapes.hpp"

namespace graspfill::mesh {
namespace {

// 2 x 2 x 16 cm, base on z = 0, centred on the z axis (synth's cuboid).
const Eigen::Vector3d kSize(0.02, 0.02, 0.16);

TriangleMesh Cuboid() { return synth::MakeShape(synth::Shape::kCuboid, kSize); }

TEST(MeshGeometryTest, SamplerIsSeededAndAreaWeighted) {
  const TriangleMesh mesh = Cuboid();
  const SurfaceSamples a = SampleSurface(mesh, 20000, 3);
  const SurfaceSamples b = SampleSurface(mesh, 20000, 3);
  const SurfaceSamples c = SampleSurface(mesh, 20000, 4);
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_TRUE(a.points == b.points);
  EXPECT_FALSE(a.points == c.points);
  // Caps are 2 * 4 cm^2 of 2 * 4 + 4 * 32 = 136 cm^2: ~5.9 % of samples.
  int on_caps = 0;
  for (const Eigen::Vector3f& n : a.normals) on_caps += std::abs(n.z()) > 0.5f;
  const double fraction = static_cast<double>(on_caps) / a.points.size();
  EXPECT_NEAR(fraction, 8.0 / 136.0, 0.006);
}

TEST(MeshGeometryTest, NothingSampledOnNoArea) {
  EXPECT_TRUE(SampleSurface(TriangleMesh{}, 100, 1).points.empty());
  EXPECT_TRUE(SampleSurface(Cuboid(), 0, 1).points.empty());
}

TEST(MeshGeometryTest, AreaVolumeAndBoundsOfACuboid) {
  const TriangleMesh mesh = Cuboid();
  EXPECT_NEAR(SurfaceArea(mesh), 2 * 0.02 * 0.02 + 4 * 0.02 * 0.16, 1e-9);
  EXPECT_NEAR(SignedVolume(mesh), 0.02 * 0.02 * 0.16, 1e-10);
  const Eigen::AlignedBox3d box = Bounds(mesh);
  EXPECT_TRUE(box.sizes().isApprox(kSize, 1e-6));
  EXPECT_NEAR(box.min().z(), 0.0, 1e-9);
}

TEST(MeshGeometryTest, ClosedOrientedOnlyWhenEveryEdgeIsPaired) {
  const TriangleMesh mesh = Cuboid();
  EXPECT_TRUE(IsClosedOriented(mesh));
  EXPECT_FALSE(IsClosedOriented(TriangleMesh{}));
  TriangleMesh open = mesh;
  open.triangles.pop_back();
  EXPECT_FALSE(IsClosedOriented(open));
  TriangleMesh flipped = mesh;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_FALSE(IsClosedOriented(flipped));
  // Turned inside out: still closed and consistent, the volume negative.
  TriangleMesh inverted = mesh;
  for (Eigen::Vector3i& t : inverted.triangles) std::swap(t[1], t[2]);
  EXPECT_TRUE(IsClosedOriented(inverted));
  EXPECT_NEAR(SignedVolume(inverted), -SignedVolume(mesh), 1e-12);
}

TEST(MeshGeometryTest, WindingNumberIsOneInsideZeroOutside) {
  const TriangleMesh mesh = Cuboid();
  EXPECT_NEAR(WindingNumber(mesh, Eigen::Vector3d(0.0, 0.0, 0.08)), 1.0, 1e-9);
  EXPECT_NEAR(WindingNumber(mesh, Eigen::Vector3d(0.005, -0.009, 0.001)), 1.0, 1e-9);
  EXPECT_NEAR(WindingNumber(mesh, Eigen::Vector3d(0.0, 0.0, 0.2)), 0.0, 1e-9);
  EXPECT_NEAR(WindingNumber(mesh, Eigen::Vector3d(0.011, 0.0, 0.08)), 0.0, 1e-9);
}

TEST(MeshGeometryTest, PointTriangleDistanceInEachRegion) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Above the face: the height.
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(0.2, 0.2, 0.5), a, b, c), 0.5, 1e-12);
  // Beyond a vertex: the distance to it.
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(-3, -4, 0), a, b, c), 5.0, 1e-12);
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(2, 0, 0), a, b, c), 1.0, 1e-12);
  // Beside an edge: the distance to the line, here to the hypotenuse.
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(1, 1, 0), a, b, c), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(0.5, -2, 0), a, b, c), 2.0, 1e-12);
  // On the triangle.
  EXPECT_NEAR(PointTriangleDistance(Eigen::Vector3d(0.25, 0.25, 0), a, b, c), 0.0, 1e-12);
}

}  // namespace
}  // namespace graspfill::mesh
