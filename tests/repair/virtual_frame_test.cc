// SPDX-License-Identifier: BSD-3-Clause
#include "virtual_frame.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>

#include "boundary_fixtures.hpp"
#include "graspfill/core/random.hpp"
#include "synth/paper_protocol.hpp"
#include "synth/shapes.hpp"

namespace graspfill::repair {
namespace {

using synth::GraspWay;
using synth::PaperProtocolCloud;
using synth::PaperProtocolConfig;
using synth::Shape;

// The paper's claim is "within a few degrees"; a least-squares plane over a
// rim of ~1 mm spaced points is good to well under a degree.
constexpr double kMaxAxisErrorDeg = 5.0;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

struct Case {
  PaperProtocolCloud cloud;
  PointList boundary;  // input frame
  testing::ProtocolHoles holes;
};

Case MakeCase(Shape shape, GraspWay grasp, uint64_t seed) {
  PaperProtocolConfig config;
  config.shape = shape;
  config.grasp = grasp;
  config.seed = seed;
  Case c;
  c.cloud = synth::MakePaperProtocolCloud(config);
  c.holes = testing::HolesOf(config, c.cloud.size_m);
  const PointList holey_O = testing::Transformed(c.cloud.holey, c.cloud.T_cloud_object.inverse());
  c.boundary = testing::Gather(c.cloud.holey, testing::OracleBoundary(holey_O, c.holes));
  return c;
}

void PrintPlanes(const Case& c, const std::vector<BoundaryPlane>& planes) {
  for (const BoundaryPlane& p : planes) {
    const Eigen::Vector3d n_O = c.cloud.T_cloud_object.linear().transpose() * p.normal;
    const Eigen::Vector3d o_O = c.cloud.T_cloud_object.inverse() * (p.offset * p.normal);
    std::printf(
        "  plane n_O (%+.3f %+.3f %+.3f) at z_O %.3f: %d inliers, Eq. 4 %.3f, open %.2f, cut %d, "
        "axis offset %.2f %s\n",
        n_O.x(), n_O.y(), n_O.z(), o_O.z(), p.inliers, p.eq4_sum, p.open_fraction, p.cut, p.axis_offset,
        p.chosen ? "<- chosen" : "");
  }
}

void ExpectFrameMatches(const Case& c, const VirtualFrame& frame, const std::string& what) {
  const Eigen::Matrix3d R = frame.T_in_V.linear();
  EXPECT_TRUE((R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-9)) << what;
  EXPECT_NEAR(R.determinant(), 1.0, 1e-9) << what;
  const Eigen::Vector3d z_true = c.cloud.T_cloud_object.linear().col(2);
  EXPECT_LT(AngleDeg(R.col(2), z_true), kMaxAxisErrorDeg) << what;
  // The cloud spans [0, top] in z: the base at 0, the cut top at the max.
  EXPECT_NEAR(frame.min_V.z(), 0.0, 1e-6) << what;
  EXPECT_NEAR(frame.max_V.z(), c.holes.top_z, 0.004) << what;
}

// Estimates c's frame from its boundary and expects it to match the truth;
// prints the planes found when it does not.
void ExpectFrameFound(const Case& c, const VirtualFrameConfig& config, const std::string& what) {
  std::string reason;
  std::vector<BoundaryPlane> planes;
  const auto frame = EstimateVirtualFrame(c.cloud.holey, c.boundary, config, nullptr, &reason, &planes);
  if (!frame) PrintPlanes(c, planes);
  ASSERT_TRUE(frame.has_value()) << what << ": " << reason;
  ExpectFrameMatches(c, *frame, what);
  if (::testing::Test::HasFailure()) PrintPlanes(c, planes);
}

TEST(VirtualFrameConfig, DefaultsAreValidAndBadValuesThrow) {
  VirtualFrameConfig config;
  EXPECT_NO_THROW(config.Validate());
  EXPECT_EQ(config.max_planes, 8);
  EXPECT_TRUE(config.prefer_open_planes);
  config.plane_distance_m = 0.0;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config = VirtualFrameConfig();
  config.ransac_confidence = 1.0;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config = VirtualFrameConfig();
  config.min_plane_inliers = 2;
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config = VirtualFrameConfig();
  config.max_boundary_axis_angle_rad = 2.0;  // past pi/2: every axis would agree
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config = VirtualFrameConfig();
  config.min_boundary_offset = std::nan("");
  EXPECT_THROW(config.Validate(), std::invalid_argument);
  config = VirtualFrameConfig();
  config.max_boundary_axis_angle_rad = 0.0;  // off
  EXPECT_NO_THROW(config.Validate());
}

// The requirement: z within a few degrees of the true axis, towards
// the cut top, for every shape in random poses (top grasps).
TEST(VirtualFrame, EveryShapeInRandomPosesTopGrasp) {
  const VirtualFrameConfig config;
  for (Shape shape : synth::AllShapes()) {
    for (uint64_t seed : {1, 2, 3, 4}) {
      const Case c = MakeCase(shape, GraspWay::kTopStraight, seed);
      const std::string what = synth::ShapeName(shape) + " seed " + std::to_string(seed);
      ExpectFrameFound(c, config, what);
      if (HasFailure()) return;
    }
  }
}

TEST(VirtualFrame, EveryShapeMiddleAndObliqueGrasps) {
  const VirtualFrameConfig config;
  for (Shape shape : synth::AllShapes()) {
    for (GraspWay grasp : {GraspWay::kMiddleStraight, GraspWay::kTopOblique}) {
      for (uint64_t seed : {11, 12}) {
        const Case c = MakeCase(shape, grasp, seed);
        const std::string what =
            synth::ShapeName(shape) + " " + synth::GraspWayName(grasp) + " seed " + std::to_string(seed);
        ExpectFrameFound(c, config, what);
        if (HasFailure()) return;
      }
    }
  }
}

// A real detector also flags sharp edges (the paper names the triangular
// prism's 60 degree edges; 90 degree ones look like inner points to the
// maximum-angle criterion) and stray points. The side faces then carry
// long boundary outlines, yet they are no cut.
TEST(VirtualFrame, RobustToSharpEdgeFalseBoundariesAndStrays) {
  const VirtualFrameConfig config;
  for (uint64_t seed : {21, 22, 23, 24}) {
    Case c = MakeCase(Shape::kTriangularPrism, GraspWay::kTopStraight, seed);
    const Eigen::Isometry3d T_O_cloud = c.cloud.T_cloud_object.inverse();
    const Eigen::Vector3d size = c.cloud.size_m;
    const std::vector<Eigen::Vector2d> corners = {
        {-2.0 * size.x() / 3.0, 0.0}, {size.x() / 3.0, 0.5 * size.y()}, {size.x() / 3.0, -0.5 * size.y()}};
    int added = 0;
    for (const Eigen::Vector3f& p : c.cloud.holey) {
      const Eigen::Vector2d xy = (T_O_cloud * p.cast<double>()).head<2>();
      for (const Eigen::Vector2d& corner : corners) {
        if ((xy - corner).norm() < 0.001) {
          c.boundary.push_back(p);
          ++added;
          break;
        }
      }
    }
    Rng rng(seed);
    const size_t strays = c.boundary.size() / 20;
    for (size_t k = 0; k < strays; ++k) {
      c.boundary.push_back(c.cloud.holey[static_cast<size_t>(rng.Uniform() * c.cloud.holey.size())]);
    }
    const std::string what = "seed " + std::to_string(seed) + " (+" + std::to_string(added) +
                             " edge points, " + std::to_string(strays) + " strays)";
    ExpectFrameFound(c, config, what);
    if (HasFailure()) return;
  }
}

// x and y follow the faces of a box (minimum-area rectangle), and the box
// in V is the cuboid's own.
TEST(VirtualFrame, CuboidAxesFollowTheFaces) {
  const Case c = MakeCase(Shape::kCuboid, GraspWay::kTopStraight, 7);
  const auto frame = EstimateVirtualFrame(c.cloud.holey, c.boundary, VirtualFrameConfig());
  ASSERT_TRUE(frame.has_value());
  const Eigen::Matrix3d R_O = c.cloud.T_cloud_object.linear();
  const Eigen::Vector3d x = frame->T_in_V.linear().col(0);
  const double to_face = std::min(
      AngleDeg(x, R_O.col(0)),
      std::min(AngleDeg(x, -R_O.col(0)), std::min(AngleDeg(x, R_O.col(1)), AngleDeg(x, -R_O.col(1)))));
  EXPECT_LT(to_face, 2.0);
  EXPECT_NEAR(frame->max_V.x() - frame->min_V.x(), c.cloud.size_m.x(), 0.002);
  EXPECT_NEAR(frame->max_V.y() - frame->min_V.y(), c.cloud.size_m.y(), 0.002);
  // The origin is on the axis: the box is centred in x and y.
  EXPECT_NEAR(frame->max_V.x() + frame->min_V.x(), 0.0, 0.002);
  EXPECT_NEAR(frame->max_V.y() + frame->min_V.y(), 0.0, 0.002);
}

// The elliptic section's longer side is x.
TEST(VirtualFrame, XIsTheLongerSide) {
  const Case c = MakeCase(Shape::kEllipticCylinder, GraspWay::kTopStraight, 8);
  const auto frame = EstimateVirtualFrame(c.cloud.holey, c.boundary, VirtualFrameConfig());
  ASSERT_TRUE(frame.has_value());
  EXPECT_NEAR(frame->max_V.x() - frame->min_V.x(), c.cloud.size_m.x(), 0.002);
  EXPECT_NEAR(frame->max_V.y() - frame->min_V.y(), c.cloud.size_m.y(), 0.002);
}

TEST(VirtualFrame, UpHintIsOptionalAndAgrees) {
  const Case c = MakeCase(Shape::kSphere, GraspWay::kTopStraight, 9);
  const VirtualFrameConfig config;
  const Eigen::Vector3d up =
      c.cloud.T_cloud_object.linear().col(2) + 0.3 * c.cloud.T_cloud_object.linear().col(0);  // ~17 deg off
  const auto with_hint = EstimateVirtualFrame(c.cloud.holey, c.boundary, config, &up);
  const auto without = EstimateVirtualFrame(c.cloud.holey, c.boundary, config);
  ASSERT_TRUE(with_hint && without);
  ExpectFrameMatches(c, *with_hint, "hint");
  EXPECT_LT(AngleDeg(with_hint->T_in_V.linear().col(2), without->T_in_V.linear().col(2)), 1e-6);
}

TEST(VirtualFrame, PaperModeEq4AloneStillFindsTheAxisOnACylinder) {
  VirtualFrameConfig config;
  config.prefer_open_planes = false;
  const Case c = MakeCase(Shape::kCylinder, GraspWay::kTopStraight, 5);
  std::vector<BoundaryPlane> planes;
  const auto frame = EstimateVirtualFrame(c.cloud.holey, c.boundary, config, nullptr, nullptr, &planes);
  ASSERT_TRUE(frame.has_value());
  ExpectFrameMatches(c, *frame, "paper mode");
  EXPECT_GE(planes.size(), 2u);
}

TEST(VirtualFrame, DeterministicForTheSameInput) {
  const Case c = MakeCase(Shape::kEllipsoid, GraspWay::kTopStraight, 3);
  const VirtualFrameConfig config;
  const auto a = EstimateVirtualFrame(c.cloud.holey, c.boundary, config);
  const auto b = EstimateVirtualFrame(c.cloud.holey, c.boundary, config);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->T_in_V.matrix() == b->T_in_V.matrix());
}

TEST(VirtualFrame, TooFewOrNoBoundaryPointsGiveAReason) {
  const Case c = MakeCase(Shape::kCylinder, GraspWay::kTopStraight, 1);
  std::string reason;
  EXPECT_FALSE(EstimateVirtualFrame(c.cloud.holey, {}, VirtualFrameConfig(), nullptr, &reason));
  EXPECT_NE(reason.find("boundary"), std::string::npos) << reason;
  reason.clear();
  EXPECT_FALSE(EstimateVirtualFrame({}, c.boundary, VirtualFrameConfig(), nullptr, &reason));
  EXPECT_NE(reason.find("no finite point"), std::string::npos) << reason;
  // NaNs are ignored, not propagated.
  PointList with_nan = c.boundary;
  with_nan.push_back(Eigen::Vector3f(NAN, 0, 0));
  const auto frame = EstimateVirtualFrame(c.cloud.holey, with_nan, VirtualFrameConfig());
  ASSERT_TRUE(frame.has_value());
  EXPECT_TRUE(frame->T_in_V.matrix().allFinite());
}

TEST(VirtualFrame, ToVirtualFrameInvertsTheFrame) {
  VirtualFrame frame;
  frame.T_in_V =
      Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  const PointList in = {Eigen::Vector3f(0.1f, -0.2f, 0.3f), Eigen::Vector3f(1, 2, 3)};
  const PointList v = ToVirtualFrame(in, frame);
  EXPECT_LT(v[0].norm(), 1e-6);
  EXPECT_LT(((frame.T_in_V.cast<float>() * v[1]) - in[1]).norm(), 1e-5);
}

// Reports wall and CPU time (the CPU time is what the step costs; the wall
// time also counts whatever else the machine runs).
TEST(VirtualFrame, Timing) {
  const Case c = MakeCase(Shape::kCylinder, GraspWay::kTopStraight, 2);
  const VirtualFrameConfig config;
  constexpr int kRuns = 10;
  const std::clock_t c0 = std::clock();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kRuns; ++i) ASSERT_TRUE(EstimateVirtualFrame(c.cloud.holey, c.boundary, config));
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / kRuns;
  const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC / kRuns;
  std::printf("EstimateVirtualFrame: %.2f ms CPU, %.2f ms wall (%zu cloud points, %zu boundary points)\n",
              cpu_ms, wall_ms, c.cloud.holey.size(), c.boundary.size());
}

}  // namespace
}  // namespace graspfill::repair
