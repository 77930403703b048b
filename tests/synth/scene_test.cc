// SPDX-License-Identifier: BSD-3-Clause
#include "synth/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "graspfill/core/pose_interpolation.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"

namespace graspfill::synth {
namespace {

// The closest finger must be within this of the object surface [m]
// (clearance 0.5 mm plus sampling slack).
constexpr double kTouchTolM = 0.001;
// A sample this far inside a finger box counts as penetration [m]
// (float rounding of the meshes).
constexpr double kPenetrationTolM = 1e-6;
constexpr double kPi = 3.14159265358979323846;

SceneConfig MakeConfig(Shape shape, ClawType claw, GraspWay grasp) {
  SceneConfig config;
  config.shape = shape;
  config.claw = claw;
  config.grasp = grasp;
  config.shape_segments = 64;  // keeps the test fast; placement is exact
  return config;
}

// Object points (dense samples plus vertices) in G.
std::vector<Eigen::Vector3d> ObjectPoints(const Scene& scene) {
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3f& p : mesh::SampleSurface(scene.object_G(), 200000, 11).points) {
    points.push_back(p.cast<double>());
  }
  for (const Eigen::Vector3f& v : scene.object_G().vertices) points.push_back(v.cast<double>());
  return points;
}

class GraspTest : public ::testing::TestWithParam<std::tuple<Shape, ClawType, GraspWay>> {};

TEST_P(GraspTest, FingersTouchButDoNotPenetrate) {
  const auto [shape, claw_type, grasp] = GetParam();
  const Scene scene(MakeConfig(shape, claw_type, grasp));
  const Placement& placement = scene.placement();
  const claw::ClawModel model = scene.MakeClawModel();
  const std::vector<Eigen::Isometry3d> T_G_link = model.LinkPoses(placement.opening_m);
  const double thickness = placement.claw.finger_thickness_m;
  const double half_width = 0.5 * placement.claw.finger_width_m;
  const double length = placement.claw.finger_length_m;
  const std::vector<Eigen::Vector3d> points = ObjectPoints(scene);

  double closest_any = 1e9;
  int fingers = 0;
  for (size_t k = 0; k < model.links().size(); ++k) {
    if (model.links()[k].joint.type != claw::JointType::kPrismatic) continue;
    ++fingers;
    // Finger link frame: x radial (inner face at x = 0), y across, z along.
    const Eigen::Isometry3d T_link_G = T_G_link[k].inverse();
    double closest = 1e9;
    for (const Eigen::Vector3d& p_G : points) {
      const Eigen::Vector3d p = T_link_G * p_G;
      const bool in_footprint = std::abs(p.y()) <= half_width && p.z() >= 0.0 && p.z() <= length;
      if (!in_footprint) continue;
      ASSERT_FALSE(p.x() > kPenetrationTolM && p.x() < thickness)
          << "finger " << k << " penetrates by " << p.x() << " m";
      closest = std::min(closest, -p.x());
    }
    closest_any = std::min(closest_any, closest);
    // Symmetric shapes under straight grasps: every finger touches.
    const bool symmetric_three =
        claw_type == ClawType::kThreeFinger && grasp != GraspWay::kTopOblique &&
        (shape == Shape::kCylinder || shape == Shape::kSphere || shape == Shape::kTriangularPrism);
    // Opposed fingers self-centre the object, so both always touch.
    const bool symmetric_two = claw_type == ClawType::kParallel;
    if (symmetric_three || symmetric_two) {
      EXPECT_LE(closest, kTouchTolM) << "finger " << k;
    }
  }
  EXPECT_EQ(fingers, claw_type == ClawType::kParallel ? 2 : 3);
  EXPECT_GE(closest_any, 0.0);
  EXPECT_LE(closest_any, kTouchTolM);
}

TEST_P(GraspTest, ObjectHangsBelowThePalmTopFirst) {
  const auto [shape, claw_type, grasp] = GetParam();
  const Scene scene(MakeConfig(shape, claw_type, grasp));
  const Placement& placement = scene.placement();
  const Eigen::AlignedBox3d box = mesh::Bounds(scene.object_G());
  EXPECT_NEAR(box.min().z(), placement.palm_gap_m, 1e-6);
  EXPECT_GE(placement.palm_gap_m, scene.config().placement.min_palm_gap_m - 1e-9);
  // Object up (+z_O) is G's -z, up to the oblique tilt.
  const Eigen::Vector3d up_G = placement.T_G_O.linear() * Eigen::Vector3d::UnitZ();
  const double tilt_deg = std::acos(-up_G.z()) * 180.0 / kPi;
  EXPECT_NEAR(tilt_deg, grasp == GraspWay::kTopOblique ? 20.0 : 0.0, 1e-6);
  // The fingertips end at the contact height plus half a pad.
  const double height = mesh::Bounds(scene.object_O()).sizes().z();
  const Eigen::Vector3d contact_G =
      placement.T_G_O * Eigen::Vector3d(0, 0, (1.0 - placement.contact_fraction) * height);
  EXPECT_NEAR(placement.claw.finger_length_m, contact_G.z() + 0.5 * scene.config().placement.finger_pad_m,
              1e-9);
  if (grasp != GraspWay::kTopOblique && claw_type == ClawType::kThreeFinger) {
    EXPECT_NEAR(contact_G.x(), 0.0, 1e-9);  // on G's axis
    EXPECT_NEAR(contact_G.y(), 0.0, 1e-9);
  }
  const Eigen::AlignedBox3d workspace = scene.WorkspaceBoxG();
  EXPECT_TRUE(workspace.contains(box));
  EXPECT_GE(workspace.min().z(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(ShapesClawsGrasps, GraspTest,
                         ::testing::Combine(::testing::ValuesIn(AllShapes()),
                                            ::testing::Values(ClawType::kThreeFinger, ClawType::kParallel),
                                            ::testing::Values(GraspWay::kTopStraight,
                                                              GraspWay::kMiddleStraight,
                                                              GraspWay::kTopOblique)),
                         [](const auto& info) {
                           std::string name = ShapeName(std::get<0>(info.param)) + "_" +
                                              ClawTypeName(std::get<1>(info.param)) + "_" +
                                              GraspWayName(std::get<2>(info.param));
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });

TEST(SceneTest, LongFingersForTallMiddleGrasps) {
  SceneConfig config = MakeConfig(Shape::kCuboid, ClawType::kThreeFinger, GraspWay::kMiddleStraight);
  config.size_m = Eigen::Vector3d(0.10, 0.10, 0.20);
  const Scene scene(config);
  // 50 % of 20 cm plus half a pad is beyond the default 9 cm fingers.
  EXPECT_NEAR(scene.placement().palm_gap_m, config.placement.min_palm_gap_m, 1e-12);
  EXPECT_NEAR(scene.placement().claw.finger_length_m, 0.005 + 0.10 + 0.01, 1e-6);
  // The default cuboid keeps the default claw.
  const Scene small(MakeConfig(Shape::kCuboid, ClawType::kThreeFinger, GraspWay::kTopStraight));
  EXPECT_DOUBLE_EQ(small.placement().claw.finger_length_m, claw::ProceduralClawConfig{}.finger_length_m);
  EXPECT_NEAR(small.placement().palm_gap_m, 0.09 - 0.035 - 0.01, 1e-6);
}

TEST(SceneTest, TimestampsAreOffsetAndCoverTheFrames) {
  const Scene scene(SceneConfig{});
  const std::vector<int64_t> depth = scene.DepthUtimes();
  const std::vector<int64_t> gripper = scene.GripperUtimes();
  ASSERT_EQ(depth.size(), 90u);
  EXPECT_EQ(depth.front(), scene.config().motion.start_utime);
  for (size_t i = 1; i < depth.size(); ++i) {
    EXPECT_NEAR(static_cast<double>(depth[i] - depth[i - 1]), 1e6 / 30.0, 1.0);
  }
  for (size_t i = 1; i < gripper.size(); ++i) EXPECT_EQ(gripper[i] - gripper[i - 1], 10000);
  const std::set<int64_t> depth_set(depth.begin(), depth.end());
  int64_t closest_us = INT64_MAX;
  for (int64_t t : gripper) {
    EXPECT_EQ(depth_set.count(t), 0u);
    for (int64_t d : depth) closest_us = std::min(closest_us, std::abs(t - d));
  }
  // 3.7 ms offset against 33.3 ms frames: nearest pair 367 us apart.
  EXPECT_GE(closest_us, 300);
  EXPECT_LT(gripper.front(), depth.front() - 50000);
  EXPECT_GT(gripper.back(), depth.back() + 50000);

  const std::vector<TimelineEvent> timeline = scene.Timeline();
  EXPECT_EQ(timeline.size(), depth.size() + gripper.size());
  EXPECT_TRUE(
      std::is_sorted(timeline.begin(), timeline.end(),
                     [](const TimelineEvent& a, const TimelineEvent& b) { return a.utime < b.utime; }));
}

TEST(SceneTest, OneTurnAboutTheGripperAxis) {
  const Scene scene(SceneConfig{});
  const double duration_s = 3.0;
  const Eigen::Isometry3d T0 = scene.T_W_G(0.0);
  const Eigen::Isometry3d Thalf = scene.T_W_G(0.5 * duration_s);
  // G's z stays roughly down (wobble 1 deg), the angle about it turns.
  for (double t : {0.0, 0.7, 1.5, 2.9}) {
    const Eigen::Vector3d z_W = scene.T_W_G(t).linear().col(2);
    EXPECT_GT(-z_W.z(), std::cos(2.0 * kPi / 180.0));
  }
  const double angle = std::atan2(T0.linear().col(0).cross(Thalf.linear().col(0)).norm(),
                                  T0.linear().col(0).dot(Thalf.linear().col(0)));
  EXPECT_NEAR(angle, kPi, 3.0 * kPi / 180.0);
  // The object's centre stays near the world origin at the camera's focus.
  const Eigen::Vector3d centre_G = mesh::Bounds(scene.object_G()).center();
  for (double t : {0.0, 1.0, 2.0}) {
    EXPECT_LT((scene.T_W_G(t) * Eigen::Vector3d(0, 0, centre_G.z())).norm(), 0.005);
  }
  const Eigen::Vector3d cam = scene.T_W_C().translation();
  EXPECT_NEAR(cam.norm(), 0.55, 1e-9);
  EXPECT_LT(cam.z(), 0.0);  // below the object
}

// --speed-variation F: the same turn, slower at the ends (1 - F times the
// mean speed) and faster in the middle (1 + F times), ending where it would.
TEST(SceneTest, SpeedVariationSlowsTheEndsAndSpeedsUpTheMiddle) {
  SceneConfig steady_config;
  steady_config.motion.wobble_deg = 0.0;  // the turn alone
  SceneConfig varying_config = steady_config;
  varying_config.motion.speed_variation = 0.5;
  const Scene steady(steady_config), varying(varying_config);
  auto turn_rad = [](const Scene& scene, double t0, double t1) {
    return Eigen::AngleAxisd(scene.T_W_G(t0).linear().transpose() * scene.T_W_G(t1).linear()).angle();
  };
  const double duration_s = 3.0, dt = 0.01;
  const double mean = turn_rad(steady, 0.0, dt);  // rad per dt
  EXPECT_NEAR(turn_rad(steady, 1.5, 1.5 + dt), mean, 1e-9);
  EXPECT_NEAR(turn_rad(varying, 0.0, dt) / mean, 0.5, 0.01);
  EXPECT_NEAR(turn_rad(varying, 1.5 - 0.5 * dt, 1.5 + 0.5 * dt) / mean, 1.5, 0.01);
  EXPECT_TRUE(varying.T_W_G(duration_s).isApprox(steady.T_W_G(duration_s), 1e-9));
  EXPECT_TRUE(varying.T_W_G(0.0).isApprox(steady.T_W_G(0.0), 1e-12));
  SceneConfig bad = steady_config;
  bad.motion.speed_variation = 1.0;  // would stop the turn
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

TEST(SceneTest, GripperStatesInterpolateToTheFramePoses) {
  SceneConfig config;
  config.grasp = GraspWay::kTopOblique;
  const Scene scene(config);
  const std::vector<int64_t> gripper = scene.GripperUtimes();
  for (int64_t t : scene.DepthUtimes()) {
    const auto after = std::upper_bound(gripper.begin(), gripper.end(), t);
    ASSERT_NE(after, gripper.begin());
    ASSERT_NE(after, gripper.end());
    const int64_t t0 = *(after - 1);
    const int64_t t1 = *after;
    const Eigen::Isometry3d interp =
        InterpolatePose(scene.GripperStateAt(t0).T_C_G, scene.GripperStateAt(t1).T_C_G,
                        static_cast<double>(t - t0) / static_cast<double>(t1 - t0));
    const Eigen::Isometry3d exact = scene.T_C_G_AtUtime(t);
    // A point on the object's far side moves < 0.1 mm through the error.
    const Eigen::Vector3d p_G(0.05, 0.05, 0.15);
    EXPECT_LT((interp * p_G - exact * p_G).norm(), 1e-4);
  }
  EXPECT_DOUBLE_EQ(scene.GripperStateAt(gripper[3]).opening_m, scene.placement().opening_m);
}

TEST(SceneTest, RejectsBadConfigs) {
  SceneConfig config;
  config.num_frames = 0;
  EXPECT_THROW(Scene{config}, std::invalid_argument);
  config = SceneConfig{};
  config.size_m = Eigen::Vector3d(-0.1, 0.1, 0.1);
  EXPECT_THROW(Scene{config}, std::invalid_argument);
  config = SceneConfig{};
  config.sensor.random_dropout_prob = 1.5;
  EXPECT_THROW(Scene{config}, std::invalid_argument);
}

TEST(SceneTest, NamesRoundTrip) {
  for (ClawType c : {ClawType::kThreeFinger, ClawType::kParallel}) {
    EXPECT_EQ(*ParseClawType(ClawTypeName(c)), c);
  }
  for (GraspWay g : {GraspWay::kTopStraight, GraspWay::kMiddleStraight, GraspWay::kTopOblique}) {
    EXPECT_EQ(*ParseGraspWay(GraspWayName(g)), g);
  }
  EXPECT_FALSE(ParseClawType("robotiq").has_value());
  EXPECT_FALSE(ParseGraspWay("bottom").has_value());
}

}  // namespace
}  // namespace graspfill::synth
