// SPDX-License-Identifier: BSD-3-Clause
// The rig error model: exact sizes for the hand-eye error, the RMS asked
// for in the noise, seeded and order-independent, off by default.
#include "synth/rig_errors.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace graspfill::synth {
namespace {

double AngleDeg(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.linear()).angle() * 180.0 / M_PI; }

TEST(RigErrors, OffByDefault) {
  const RigErrors rig(RigErrorConfig{}, 7);
  EXPECT_FALSE(RigErrorConfig{}.any());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.1, -0.2, 0.5);
  EXPECT_TRUE(rig.Logged(T, 12).isApprox(T));
  EXPECT_EQ(rig.TrueUtime(1000), 1000);
}

TEST(RigErrors, HandEyeErrorHasExactlyTheSizeAsked) {
  RigErrorConfig c;
  c.hand_eye_m = 0.003;
  c.hand_eye_deg = 1.0;
  const RigErrors a(c, 1), b(c, 1), other(c, 2);
  EXPECT_NEAR(a.hand_eye_error().translation().norm(), 0.003, 1e-12);
  EXPECT_NEAR(AngleDeg(a.hand_eye_error()), 1.0, 1e-9);
  EXPECT_TRUE(a.hand_eye_error().isApprox(b.hand_eye_error()));  // seeded
  EXPECT_FALSE(a.hand_eye_error().isApprox(other.hand_eye_error()));
}

TEST(RigErrors, NoiseHasTheRmsAskedAndDependsOnTheStateOnly) {
  RigErrorConfig c;
  c.pose_noise_m = 0.0005;
  c.pose_noise_deg = 0.2;
  c.clock_offset_us = 15000;
  const RigErrors rig(c, 3);
  double sum_t2 = 0.0, sum_a2 = 0.0;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    const Eigen::Isometry3d N = rig.StateNoise(k);
    sum_t2 += N.translation().squaredNorm();
    sum_a2 += std::pow(AngleDeg(N), 2);
  }
  EXPECT_NEAR(std::sqrt(sum_t2 / n), 0.0005, 0.00003);
  EXPECT_NEAR(std::sqrt(sum_a2 / n), 0.2, 0.012);
  EXPECT_TRUE(rig.StateNoise(17).isApprox(RigErrors(c, 3).StateNoise(17)));
  EXPECT_FALSE(rig.StateNoise(17).isApprox(rig.StateNoise(18)));
  EXPECT_EQ(rig.TrueUtime(1000000), 1015000);
}

TEST(RigErrors, BadConfigIsRejected) {
  RigErrorConfig c;
  c.hand_eye_deg = -1.0;
  EXPECT_THROW(RigErrors(c, 1), std::invalid_argument);
  c = RigErrorConfig{};
  c.clock_offset_us = 2000000;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::synth
