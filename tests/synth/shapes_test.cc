#include "graspfill/synth/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "graspfill/synth/mesh_sampling.hpp"

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
       {DefaultSize(shape), Eigen::Vector3d(0.10, 0.10, 0.20),
        Eigen::Vector3d(0.05, 0.05, 0.10)}) {
    const TriangleMesh mesh = MakeShape(shape, size);
    EXPECT_TRUE(IsClosedOriented(mesh)) << ShapeName(shape);
    const double expected = AnalyticVolume(shape, size);
    EXPECT_NEAR(SignedVolume(mesh), expected, kVolumeRelTol * expected)
        << ShapeName(shape);
  }
}

TEST_P(ShapeTest, BoundingBoxFollowsTheObjectFrame) {
  const Shape shape = GetParam();
  const Eigen::Vector3d size = DefaultSize(shape);
  const Eigen::AlignedBox3d box = Bounds(MakeShape(shape, size));
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
  const SurfaceSamples samples = SampleSurface(mesh, 2000, 7);
  ASSERT_EQ(samples.points.size(), 2000u);
  ASSERT_EQ(samples.normals.size(), 2000u);
  for (size_t k = 0; k < samples.points.size(); ++k) {
    const Eigen::Vector3d p = samples.points[k].cast<double>();
    double best = 1e9;
    for (const Eigen::Vector3i& t : mesh.triangles) {
      best = std::min(best, PointTriangleDistance(p, mesh.vertices[t[0]].cast<double>(),
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

INSTANTIATE_TEST_SUITE_P(AllShapes, ShapeTest, ::testing::ValuesIn(AllShapes()),
                         [](const ::testing::TestParamInfo<Shape>& info) {
                           std::string name = ShapeName(info.param);
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });

TEST(ShapesTest, DefaultSizesAreThePapers) {
  EXPECT_TRUE(DefaultSize(Shape::kCuboid).isApprox(Eigen::Vector3d(0.07, 0.07, 0.14)));
  EXPECT_FALSE(ParseShape("cube").has_value());
}

TEST(ShapesTest, RejectsBadSizes) {
  EXPECT_THROW(MakeShape(Shape::kCuboid, Eigen::Vector3d(0.0, 0.1, 0.1)),
               std::invalid_argument);
  EXPECT_THROW(MakeShape(Shape::kCylinder, Eigen::Vector3d(0.1, 0.1, 0.1), 3),
               std::invalid_argument);
}

TEST(MeshSamplingTest, SamplerIsSeededAndAreaWeighted) {
  const TriangleMesh mesh = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.02, 0.02, 0.16));
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

TEST(MeshSamplingTest, NormalizeToObjectFrame) {
  TriangleMesh mesh = MakeShape(Shape::kCuboid, Eigen::Vector3d(0.04, 0.06, 0.1));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.3, -0.2, 0.5);
  const Eigen::AlignedBox3d box = Bounds(NormalizeToObjectFrame(mesh.Transformed(T)));
  EXPECT_NEAR(box.center().x(), 0.0, 1e-6);
  EXPECT_NEAR(box.center().y(), 0.0, 1e-6);
  EXPECT_NEAR(box.min().z(), 0.0, 1e-6);
}

}  // namespace
}  // namespace graspfill::synth
