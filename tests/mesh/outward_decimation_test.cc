// SPDX-License-Identifier: BSD-3-Clause
#include "outward_decimation.hpp"

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "farthest_outside.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "open3d_watertight.hpp"

namespace graspfill::mesh {
namespace {

TriangleMesh FromOpen3d(const open3d::geometry::TriangleMesh& o) {
  TriangleMesh m;
  for (const Eigen::Vector3d& v : o.vertices_) m.vertices.push_back(v.cast<float>());
  m.triangles = o.triangles_;
  return m;
}

// A torus (genus 1) with its tube's outer half pushed in by a groove: a
// closed mesh with concave and saddle regions.
TriangleMesh GroovedTorus() {
  auto torus = open3d::geometry::TriangleMesh::CreateTorus(0.04, 0.015, 120, 60);
  for (Eigen::Vector3d& v : torus->vertices_) {
    const double ring = std::hypot(v.x(), v.y());
    const double groove = 0.004 * std::exp(-std::pow(v.z() / 0.004, 2)) * (ring > 0.04 ? 1.0 : 0.0);
    v.x() *= (ring - groove) / ring;
    v.y() *= (ring - groove) / ring;
  }
  return FromOpen3d(*torus);
}

// Farthest distance of `mesh`'s vertices from the sphere of radius r.
double FarthestFromSphere(const TriangleMesh& mesh, double r) {
  double farthest = 0.0;
  for (const Eigen::Vector3f& v : mesh.vertices)
    farthest = std::max(farthest, std::abs(v.cast<double>().norm() - r));
  return farthest;
}

TEST(OutwardDecimation, ASphereStaysClosedAndHoldsTheDenseMesh) {
  const double r = 0.03;
  const TriangleMesh dense = FromOpen3d(*open3d::geometry::TriangleMesh::CreateSphere(r, 60));
  ASSERT_TRUE(testing::Open3dWatertight(dense));
  ASSERT_GT(dense.triangles.size(), 6000u);

  const OutwardDecimation out = DecimateOutward(dense, 500);
  EXPECT_TRUE(out.reached_budget);
  EXPECT_LE(out.mesh.triangles.size(), 500u);
  EXPECT_GE(out.mesh.triangles.size(), 490u);  // two triangles go per collapse
  EXPECT_TRUE(testing::Open3dWatertight(out.mesh));
  EXPECT_GT(mesh::SignedVolume(out.mesh), 0.0);  // still facing outwards
  // Every dense vertex inside: the hull never cuts in (1e-6 m: float
  // rounding of the output).
  EXPECT_LT(testing::FarthestOutside(out.mesh, dense.vertices), 1e-6);
  // And it does not balloon: 500 triangles on a 3 cm sphere are ~3 mm
  // across; a tangent facet stands off the sphere by well under 1 mm.
  EXPECT_LT(FarthestFromSphere(out.mesh, r), 0.001);
}

TEST(OutwardDecimation, AGroovedTorusKeepsItsHoleAndHoldsTheDenseMesh) {
  const TriangleMesh dense = GroovedTorus();
  ASSERT_TRUE(testing::Open3dWatertight(dense));
  const OutwardDecimation out = DecimateOutward(dense, 800);
  EXPECT_TRUE(out.reached_budget);
  EXPECT_LE(out.mesh.triangles.size(), 800u);
  EXPECT_TRUE(testing::Open3dWatertight(out.mesh));
  // Genus 1 kept: V - E + F = 0.
  const int64_t v = static_cast<int64_t>(out.mesh.vertices.size());
  const int64_t f = static_cast<int64_t>(out.mesh.triangles.size());
  EXPECT_EQ(v - 3 * f / 2 + f, 0);
  EXPECT_LT(testing::FarthestOutside(out.mesh, dense.vertices), 1e-6);
  // The hole in the middle stays open: its centre is outside.
  EXPECT_LT(mesh::WindingNumber(out.mesh, Eigen::Vector3d::Zero()), 0.5);
}

TEST(OutwardDecimation, ABoxIsAlreadyAsSmallAsItCanBe) {
  // A box's 12 triangles: every collapse would cut a corner off or bulge
  // a face, and the corners' planes allow only the corner itself, where a
  // triangle would vanish. None is allowed.
  const TriangleMesh box = FromOpen3d(*open3d::geometry::TriangleMesh::CreateBox(0.05, 0.03, 0.02));
  const OutwardDecimation out = DecimateOutward(box, 4);
  EXPECT_FALSE(out.reached_budget);
  EXPECT_TRUE(testing::Open3dWatertight(out.mesh));
  EXPECT_LT(testing::FarthestOutside(out.mesh, box.vertices), 1e-6);
}

TEST(OutwardDecimation, IsDeterministic) {
  const TriangleMesh dense = GroovedTorus();
  const OutwardDecimation first = DecimateOutward(dense, 1000);
  const OutwardDecimation second = DecimateOutward(dense, 1000);
  ASSERT_EQ(first.mesh.vertices.size(), second.mesh.vertices.size());
  ASSERT_EQ(first.mesh.triangles.size(), second.mesh.triangles.size());
  for (size_t i = 0; i < first.mesh.vertices.size(); ++i) {
    EXPECT_EQ(first.mesh.vertices[i], second.mesh.vertices[i]);
  }
  for (size_t i = 0; i < first.mesh.triangles.size(); ++i) {
    EXPECT_EQ(first.mesh.triangles[i], second.mesh.triangles[i]);
  }
}

TEST(OutwardDecimation, RefusesWhatIsNotAClosedOrientedMesh) {
  TriangleMesh box = FromOpen3d(*open3d::geometry::TriangleMesh::CreateBox(0.05, 0.03, 0.02));
  EXPECT_THROW(DecimateOutward(box, 3), std::invalid_argument);

  TriangleMesh open_box = box;
  open_box.triangles.pop_back();
  EXPECT_THROW(DecimateOutward(open_box, 6), std::invalid_argument);

  TriangleMesh flipped = box;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_THROW(DecimateOutward(flipped, 6), std::invalid_argument);

  TriangleMesh bad_index = box;
  bad_index.triangles[0][0] = 99;
  EXPECT_THROW(DecimateOutward(bad_index, 6), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::mesh
