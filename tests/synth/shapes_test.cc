// SPDX-License-Identifier: BSD-3-Clause
#include "synth/shapes.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>

#include "graspfill/mesh/mesh_geometry.hpp"
#include "synth/internal/zoo_shapes.hpp"
#include "synth/scene.hpp"

namespace graspfill::synth {
namespace {

// Faceting with 128 segments loses < 0.1 % of the volume; allow 1 %.
constexpr double kVolumeRelTol = 0.01;
// Sampled points are interpolated in double and stored as float: a few
// nanometers off the plane of their triangle at 10 cm.
constexpr double kOnSurfaceTolM = 1e-6;

class ShapeTest : public ::testing::TestWithParam<Shape> {};

TEST_P(ShapeTest, ClosedOrientedWithAnalyticVolume) {
  const Shape shape = GetParam();
  for (const Eigen::Vector3d& size :
       {DefaultSize(shape), Eigen::Vector3d(0.10, 0.10, 0.20), Eigen::Vector3d(0.05, 0.05, 0.10)}) {
    const TriangleMesh mesh = MakeShape(shape, size);
    EXPECT_TRUE(mesh::IsClosedOriented(mesh)) << ShapeName(shape);
    const double expected = AnalyticVolume(shape, size);
    EXPECT_NEAR(mesh::SignedVolume(mesh), expected, kVolumeRelTol * expected) << ShapeName(shape);
  }
}

TEST_P(ShapeTest, BoundingBoxFollowsTheObjectFrame) {
  const Shape shape = GetParam();
  const Eigen::Vector3d size = DefaultSize(shape);
  const Eigen::AlignedBox3d box = mesh::Bounds(MakeShape(shape, size));
  // Faceted curves touch the bounding box at their vertices (segment 0 is
  // on +x), so the box matches the size to float precision.
  EXPECT_NEAR(box.min().z(), 0.0, 1e-7);
  EXPECT_NEAR(box.max().z(), size.z(), 1e-6);
  EXPECT_NEAR(box.sizes().x(), size.x(), 1e-6);
  EXPECT_NEAR(box.sizes().y(), size.y(), 1e-6);
  if (shape != Shape::kTriangularPrism) {
    EXPECT_NEAR(box.center().x(), 0.0, 1e-6);
    EXPECT_NEAR(box.center().y(), 0.0, 1e-6);
  }
}

TEST_P(ShapeTest, SamplesLieOnTheSurface) {
  const Shape shape = GetParam();
  const TriangleMesh mesh = MakeShape(shape, DefaultSize(shape), 32);
  const mesh::SurfaceSamples samples = mesh::SampleSurface(mesh, 2000, 7);
  ASSERT_EQ(samples.points.size(), 2000u);
  ASSERT_EQ(samples.normals.size(), 2000u);
  for (size_t k = 0; k < samples.points.size(); ++k) {
    const Eigen::Vector3d p = samples.points[k].cast<double>();
    double best = 1e9;
    for (const Eigen::Vector3i& t : mesh.triangles) {
      best = std::min(best, mesh::PointTriangleDistance(p, mesh.vertices[t[0]].cast<double>(),
                                                        mesh.vertices[t[1]].cast<double>(),
                                                        mesh.vertices[t[2]].cast<double>()));
    }
    ASSERT_LT(best, kOnSurfaceTolM) << ShapeName(shape) << " sample " << k;
    EXPECT_NEAR(samples.normals[k].norm(), 1.0f, 1e-5f);
  }
}

TEST_P(ShapeTest, NameRoundTrip) {
  const Shape shape = GetParam();
  ASSERT_TRUE(ParseShape(ShapeName(shape)).has_value());
  EXPECT_EQ(*ParseShape(ShapeName(shape)), shape);
}

std::string TestName(const ::testing::TestParamInfo<Shape>& info) {
  std::string name = ShapeName(info.param);
  for (char& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(AllShapes, ShapeTest, ::testing::ValuesIn(AllShapes()), TestName);

// --- the zoo -----------------------------------------------------------------

// Blob vertices lie on the exact surface, but its extreme points fall
// between them: at most the sag of half a 2 pi / 128 step, 3e-4 of the
// radius (12 um at 4 cm). The other zoo shapes touch their box at vertices.
constexpr double kZooBoxTolM = 2e-5;
// Smallest triangle area that is not a welding leftover [m^2] (the blob's
// pole fans are ~1e-8 m^2 at 128 segments).
constexpr double kMinTriangleAreaM2 = 1e-12;

// A second size per shape, off its default in every axis (anisotropic, so
// the bowl's and bottle's sections become ellipses).
Eigen::Vector3d OtherSize(Shape shape) {
  return DefaultSize(shape).cwiseProduct(Eigen::Vector3d(1.25, 1.1, 0.9));
}

double SmallestTriangleArea(const TriangleMesh& mesh) {
  double smallest = 1e9;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    smallest = std::min(smallest, 0.5 * (b - a).cross(c - a).norm());
  }
  return smallest;
}

// Volume centroid by the divergence theorem (tetrahedra from the origin).
Eigen::Vector3d Centroid(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    const double v = a.dot(b.cross(c));
    six_volume += v;
    moment += v * (a + b + c) / 4.0;
  }
  return moment / six_volume;
}

// Crossings of the ray p + s d (s > 0) with the mesh (Moller-Trumbore).
int Crossings(const TriangleMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
  int count = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d e1 = mesh.vertices[t[1]].cast<double>() - a;
    const Eigen::Vector3d e2 = mesh.vertices[t[2]].cast<double>() - a;
    const Eigen::Vector3d q = d.cross(e2);
    const double det = e1.dot(q);
    if (std::abs(det) < 1e-18) continue;
    const Eigen::Vector3d r = p - a;
    const double u = r.dot(q) / det;
    const Eigen::Vector3d w = r.cross(e1);
    const double v = d.dot(w) / det;
    const double s = e2.dot(w) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && s > 0.0) ++count;
  }
  return count;
}

// Inside by ray parity; three skew directions must agree (an odd count
// from one and even from another would mean a hole in the surface).
bool Inside(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  const std::array<Eigen::Vector3d, 3> directions = {Eigen::Vector3d(0.83, 0.47, 0.29).normalized(),
                                                     Eigen::Vector3d(-0.31, 0.71, -0.63).normalized(),
                                                     Eigen::Vector3d(0.13, -0.37, 0.92).normalized()};
  std::set<int> parities;
  for (const Eigen::Vector3d& d : directions) parities.insert(Crossings(mesh, p, d) % 2);
  EXPECT_EQ(parities.size(), 1u) << "rays disagree at " << p.transpose();
  return *parities.begin() == 1;
}

class ZooShapeTest : public ::testing::TestWithParam<Shape> {};

TEST_P(ZooShapeTest, ClosedOrientedWithAnalyticVolume) {
  const Shape shape = GetParam();
  for (const Eigen::Vector3d& size : {DefaultSize(shape), OtherSize(shape)}) {
    const TriangleMesh mesh = MakeShape(shape, size);
    EXPECT_TRUE(mesh::IsClosedOriented(mesh)) << ShapeName(shape);
    EXPECT_GT(SmallestTriangleArea(mesh), kMinTriangleAreaM2) << ShapeName(shape);
    const double expected = AnalyticVolume(shape, size);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(mesh::SignedVolume(mesh), expected, kVolumeRelTol * expected)
        << ShapeName(shape) << " " << size.transpose();
  }
}

TEST_P(ZooShapeTest, FollowsSegments) {
  // Coarse facets: still closed; the volume is off by more than at 128
  // segments but stays within a few percent (chords cut the curves).
  const Shape shape = GetParam();
  const Eigen::Vector3d size = DefaultSize(shape);
  const TriangleMesh coarse = MakeShape(shape, size, 16);
  const TriangleMesh fine = MakeShape(shape, size, 128);
  EXPECT_TRUE(mesh::IsClosedOriented(coarse));
  EXPECT_LT(4 * coarse.triangles.size(), fine.triangles.size());
  const double expected = AnalyticVolume(shape, size);
  const double coarse_error = std::abs(mesh::SignedVolume(coarse) - expected);
  EXPECT_LT(coarse_error, 0.08 * expected);
  EXPECT_GT(coarse_error, std::abs(mesh::SignedVolume(fine) - expected));
}

TEST_P(ZooShapeTest, BoundingBoxMatchesTheSize) {
  const Shape shape = GetParam();
  for (const Eigen::Vector3d& size : {DefaultSize(shape), OtherSize(shape)}) {
    const Eigen::AlignedBox3d box = mesh::Bounds(MakeShape(shape, size));
    EXPECT_NEAR(box.min().z(), 0.0, kZooBoxTolM) << ShapeName(shape);
    EXPECT_NEAR(box.max().z(), size.z(), kZooBoxTolM) << ShapeName(shape);
    for (int axis = 0; axis < 2; ++axis) {
      EXPECT_NEAR(box.min()[axis], -0.5 * size[axis], kZooBoxTolM) << ShapeName(shape);
      EXPECT_NEAR(box.max()[axis], 0.5 * size[axis], kZooBoxTolM) << ShapeName(shape);
    }
  }
}

TEST_P(ZooShapeTest, NameRoundTripAndDeterminism) {
  const Shape shape = GetParam();
  ASSERT_TRUE(ParseShape(ShapeName(shape)).has_value());
  EXPECT_EQ(*ParseShape(ShapeName(shape)), shape);
  const TriangleMesh a = MakeShape(shape, DefaultSize(shape), 32);
  const TriangleMesh b = MakeShape(shape, DefaultSize(shape), 32);
  EXPECT_TRUE(a.vertices == b.vertices);
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST_P(ZooShapeTest, DefaultSizeIsHeldByBothClaws) {
  const Shape shape = GetParam();
  for (ClawType claw : {ClawType::kThreeFinger, ClawType::kParallel}) {
    for (GraspWay grasp : {GraspWay::kTopStraight, GraspWay::kMiddleStraight, GraspWay::kTopOblique}) {
      SceneConfig config;
      config.shape = shape;
      config.claw = claw;
      config.grasp = grasp;
      config.shape_segments = 64;
      const std::string what = ShapeName(shape) + " " + ClawTypeName(claw) + " " + GraspWayName(grasp);
      std::optional<Scene> scene;
      ASSERT_NO_THROW(scene.emplace(config)) << what;
      const Placement& placement = scene->placement();
      // Every finger stands off the axis, the closest one touches, and the
      // object hangs below the palm with its top at least the minimum gap
      // away from it.
      const double clearance = config.placement.finger_clearance_m;
      double closest = 1e9;
      for (double r : placement.finger_touch_radius_m) {
        EXPECT_GT(r, 0.0) << what;
        closest = std::min(closest, placement.opening_m - clearance - r);
      }
      EXPECT_NEAR(closest, 0.0, 1e-9) << what;
      EXPECT_GE(placement.palm_gap_m, config.placement.min_palm_gap_m - 1e-9) << what;
      EXPECT_NEAR(mesh::Bounds(scene->object_G()).min().z(), placement.palm_gap_m, 1e-6) << what;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Zoo, ZooShapeTest, ::testing::ValuesIn(ZooShapes()), TestName);

TEST(ZooTest, KeptApartFromThePaperShapes) {
  EXPECT_EQ(AllShapes().size(), 6u);
  EXPECT_EQ(ZooShapes().size(), 5u);
  for (Shape zoo : ZooShapes()) {
    for (Shape paper : AllShapes()) EXPECT_NE(zoo, paper);
  }
  EXPECT_EQ(ParseShape("mug"), Shape::kMug);
  EXPECT_EQ(ParseShape("rounded-box"), Shape::kRoundedBox);
  EXPECT_FALSE(ParseShape("Mug").has_value());
  EXPECT_FALSE(ParseShape("can").has_value());
}

TEST(ZooTest, MugIsAsymmetricAboutXButTheBottleIsNot) {
  // The mug's body sits on -x and its handle on +x: the centroid is off
  // the box centre by ~13 mm in x but not in y (the handle is in y = 0).
  const Eigen::Vector3d mug = Centroid(MakeShape(Shape::kMug, DefaultSize(Shape::kMug)));
  EXPECT_LT(mug.x(), -0.005);
  EXPECT_NEAR(mug.y(), 0.0, 1e-6);
  // The handle stands off the body: the middle of its tube is inside the
  // solid, the middle of the gap between tube and body (x = D/2 - tube
  // radius in the box frame) is not.
  const Eigen::Vector3d size = DefaultSize(Shape::kMug);
  const TriangleMesh mesh = MakeShape(Shape::kMug, size);
  const double tube_radius = internal::kMugTubeFraction * (size.x() - size.y());
  EXPECT_TRUE(Inside(mesh, {0.5 * size.x() - tube_radius, 0.0, 0.5 * size.z()}));
  EXPECT_FALSE(Inside(mesh, {0.5 * size.y() - tube_radius, 0.0, 0.5 * size.z()}));
  const Eigen::Vector3d bottle = Centroid(MakeShape(Shape::kBottle, DefaultSize(Shape::kBottle)));
  EXPECT_NEAR(bottle.x(), 0.0, 1e-6);
  EXPECT_NEAR(bottle.y(), 0.0, 1e-6);
}

TEST(ZooTest, MugHandleOutsideTheBoxIsRejected) {
  EXPECT_THROW(MakeShape(Shape::kMug, Eigen::Vector3d(0.08, 0.08, 0.1)), std::invalid_argument);
  EXPECT_THROW(MakeShape(Shape::kMug, Eigen::Vector3d(0.2, 0.08, 0.1)), std::invalid_argument);
  EXPECT_THROW(AnalyticVolume(Shape::kMug, Eigen::Vector3d(0.07, 0.08, 0.1)), std::invalid_argument);
}

TEST(ZooTest, BowlHasAnInnerSurface) {
  const Eigen::Vector3d size = DefaultSize(Shape::kBowl);
  const TriangleMesh mesh = MakeShape(Shape::kBowl, size);
  const double wall = internal::BowlWall(size);
  EXPECT_NEAR(wall, 0.004, 1e-12);
  // Just above the inside bottom and in the middle of the cavity: outside
  // the solid; inside the bottom's wall and the side wall: inside.
  EXPECT_FALSE(Inside(mesh, {0.0, 0.0, wall + 0.001}));
  EXPECT_FALSE(Inside(mesh, {0.0, 0.0, 0.5 * size.z()}));
  EXPECT_TRUE(Inside(mesh, {0.0, 0.0, 0.5 * wall}));
  EXPECT_TRUE(Inside(mesh, {0.5 * size.x() - 0.5 * wall, 0.0, size.z() - 0.001}));
  // The rim is flat: every vertex at the top lies on z = H, and some do.
  int rim = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) rim += std::abs(v.z() - size.z()) < 1e-6;
  EXPECT_EQ(rim, 2 * 128);  // outer and inner rim circles
}

TEST(ZooTest, RoundedBoxRoundsEveryEdgeButKeepsFlatFaces) {
  const Eigen::Vector3d size = DefaultSize(Shape::kRoundedBox);
  const TriangleMesh mesh = MakeShape(Shape::kRoundedBox, size);
  const double inset = 0.0005;  // well inside the 6 mm edge radius
  const Eigen::Vector3d half = 0.5 * size;
  EXPECT_TRUE(Inside(mesh, {half.x() - inset, 0.0, half.z()}));                // side face
  EXPECT_TRUE(Inside(mesh, {0.0, 0.0, size.z() - inset}));                     // top face
  EXPECT_FALSE(Inside(mesh, {half.x() - inset, half.y() - inset, half.z()}));  // vertical edge
  EXPECT_FALSE(Inside(mesh, {half.x() - inset, 0.0, size.z() - inset}));       // top edge
  EXPECT_FALSE(Inside(mesh, {0.0, half.y() - inset, inset}));                  // bottom edge
}

TEST(ZooTest, BottleHasANarrowNeck) {
  const Eigen::Vector3d size = DefaultSize(Shape::kBottle);
  const TriangleMesh mesh = MakeShape(Shape::kBottle, size);
  Eigen::AlignedBox3d neck;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    if (v.z() > 0.9 * size.z()) neck.extend(v.cast<double>());
  }
  EXPECT_NEAR(neck.sizes().x(), internal::kBottleNeckFraction * size.x(), 1e-6);
  EXPECT_NEAR(neck.sizes().y(), internal::kBottleNeckFraction * size.y(), 1e-6);
}

TEST(ZooTest, BlobIsLumpyWithoutMirrorPlanes) {
  const Eigen::Vector3d size = DefaultSize(Shape::kBlob);
  const TriangleMesh mesh = MakeShape(Shape::kBlob, size);
  // Off the ellipsoid inscribed in its box by a few percent, not more.
  double worst = 0.0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    const Eigen::Vector3d q(v.x() / (0.5 * size.x()), v.y() / (0.5 * size.y()),
                            (v.z() - 0.5 * size.z()) / (0.5 * size.z()));
    worst = std::max(worst, std::abs(q.norm() - 1.0));
  }
  EXPECT_GT(worst, 0.02);
  EXPECT_LT(worst, 0.15);
  // The centroid is off the box centre in all three axes (0.4-1 mm), so
  // no plane through the centre normal to an axis mirrors it.
  const Eigen::Vector3d c = Centroid(mesh) - Eigen::Vector3d(0.0, 0.0, 0.5 * size.z());
  EXPECT_GT(c.cwiseAbs().minCoeff(), 1e-4) << c.transpose();
}

TEST(ShapesTest, DefaultSizesAreThePapers) {
  EXPECT_TRUE(DefaultSize(Shape::kCuboid).isApprox(Eigen::Vector3d(0.07, 0.07, 0.14)));
  EXPECT_FALSE(ParseShape("cube").has_value());
}

TEST(ShapesTest, RejectsBadSizes) {
  EXPECT_THROW(MakeShape(Shape::kCuboid, Eigen::Vector3d(0.0, 0.1, 0.1)), std::invalid_argument);
  EXPECT_THROW(MakeShape(Shape::kCylinder, Eigen::Vector3d(0.1, 0.1, 0.1), 3), std::invalid_argument);
}

TEST(ShapesTest, NormalizeToObjectFrame) {
  TriangleMesh mesh = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.04, 0.06, 0.1));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.3, -0.2, 0.5);
  const Eigen::AlignedBox3d box = mesh::Bounds(NormalizeToObjectFrame(mesh.Transformed(T)));
  EXPECT_NEAR(box.center().x(), 0.0, 1e-6);
  EXPECT_NEAR(box.center().y(), 0.0, 1e-6);
  EXPECT_NEAR(box.min().z(), 0.0, 1e-6);
}

}  // namespace
}  // namespace graspfill::synth
