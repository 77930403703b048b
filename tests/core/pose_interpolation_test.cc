// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/pose_interpolation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace graspfill {
namespace {

// A gripper turning about its z axis at a constant rate, 10 cm from the
// camera origin along +z, moving 1 cm/s in x.
Eigen::Isometry3d TrueMotion(double t_s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.8 * t_s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.01 * t_s, 0.0, 0.1);
  return T;
}

GripperState StateAt(int64_t utime) {
  GripperState s;
  s.utime = utime;
  s.T_C_G = TrueMotion(utime * 1e-6);
  s.opening_m = 0.03 + 0.001 * utime * 1e-6;
  return s;
}

TEST(InterpolatePose, EndpointsAndMidpoint) {
  const Eigen::Isometry3d a = TrueMotion(0.0), b = TrueMotion(0.5);
  EXPECT_TRUE(InterpolatePose(a, b, 0.0).isApprox(a, 1e-12));
  EXPECT_TRUE(InterpolatePose(a, b, 1.0).isApprox(b, 1e-12));
  // Constant angular velocity: the slerp midpoint is the true midpoint.
  EXPECT_TRUE(InterpolatePose(a, b, 0.5).isApprox(TrueMotion(0.25), 1e-9));
}

TEST(GripperStateBuffer, InterpolatesBetweenUnalignedStates) {
  GripperStateBuffer buffer(16, 20000);
  for (int64_t t = 3700; t < 100000; t += 10000) ASSERT_TRUE(buffer.Push(StateAt(t)));
  GripperState out;
  // A 30 Hz depth timestamp between two 100 Hz states.
  ASSERT_EQ(buffer.Lookup(33333, &out), PoseLookup::kOk);
  EXPECT_EQ(out.utime, 33333);
  EXPECT_TRUE(out.T_C_G.isApprox(TrueMotion(0.033333), 1e-9));
  EXPECT_NEAR(out.opening_m, StateAt(33333).opening_m, 1e-12);
}

TEST(GripperStateBuffer, ReportsNotYetTooEarlyAndGap) {
  GripperStateBuffer buffer(4, 15000);
  GripperState out;
  EXPECT_EQ(buffer.Lookup(0, &out), PoseLookup::kNotYet);
  buffer.Push(StateAt(10000));
  buffer.Push(StateAt(20000));
  buffer.Push(StateAt(60000));  // 40 ms hole in the states
  EXPECT_EQ(buffer.Lookup(70000, &out), PoseLookup::kNotYet);
  EXPECT_EQ(buffer.Lookup(5000, &out), PoseLookup::kTooEarly);
  EXPECT_EQ(buffer.Lookup(40000, &out), PoseLookup::kGap);
  EXPECT_EQ(buffer.Lookup(15000, &out), PoseLookup::kOk);
}

TEST(GripperStateBuffer, RingDropsOldestAndRejectsBadStates) {
  GripperStateBuffer buffer(3, 20000);
  for (int64_t t = 0; t <= 40000; t += 10000) buffer.Push(StateAt(t));
  EXPECT_EQ(buffer.size(), 3u);
  EXPECT_EQ(buffer.oldest_utime(), 20000);
  EXPECT_FALSE(buffer.Push(StateAt(40000)));  // not newer
  GripperState nan_state = StateAt(50000);
  nan_state.T_C_G.translation().x() = std::nan("");
  EXPECT_FALSE(buffer.Push(nan_state));
  GripperState skewed = StateAt(50000);
  skewed.T_C_G.linear() *= 2.0;  // not a rotation
  EXPECT_FALSE(buffer.Push(skewed));
  EXPECT_EQ(buffer.newest_utime(), 40000);
}

// Issue 12: states at INT64_MIN and INT64_MAX: their difference wrapped
// to -1, passed the gap test and interpolated a bogus pose.
TEST(GripperStateBuffer, ExtremeTimestampsAreAGapNotAnOverflow) {
  GripperStateBuffer buffer(4, 50000);
  ASSERT_TRUE(buffer.Push(StateAt(INT64_MIN)));
  ASSERT_TRUE(buffer.Push(StateAt(INT64_MAX)));
  GripperState out;
  EXPECT_EQ(buffer.Lookup(0, &out), PoseLookup::kGap);
  EXPECT_EQ(buffer.Lookup(INT64_MAX - 1, &out), PoseLookup::kGap);
}

}  // namespace
}  // namespace graspfill
