// SPDX-License-Identifier: BSD-3-Clause
// The slip model: off by default, the distance asked for in a seeded
// direction near +z_G, a start in the middle of the recording, eased (no
// jump) over the duration asked for.
#include "synth/object_slip.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace graspfill::synth {
namespace {

constexpr int64_t kFirst = 1700000000000000;
constexpr int64_t kLast = kFirst + 2966667;  // 90 frames at 30 Hz

SlipConfig Slip(double distance_m) {
  SlipConfig c;
  c.distance_m = distance_m;
  return c;
}

TEST(ObjectSlip, OffByDefault) {
  EXPECT_FALSE(SlipConfig{}.any());
  const ObjectSlip slip(SlipConfig{}, 7, kFirst, kLast);
  for (int64_t t : {kFirst - 1000, kFirst, (kFirst + kLast) / 2, kLast, kLast + 1000000}) {
    EXPECT_TRUE(slip.S_G(t).isApprox(Eigen::Isometry3d::Identity())) << t;
    EXPECT_EQ(slip.Progress(t), 0.0);
  }
  EXPECT_TRUE(slip.S_G_final().isApprox(Eigen::Isometry3d::Identity()));
}

TEST(ObjectSlip, SlidesTheDistanceAskedAlongTheFingers) {
  const SlipConfig c = Slip(0.003);
  const double cos_max = std::cos(c.max_tilt_deg * M_PI / 180.0);
  double max_sideways = 0.0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    const ObjectSlip slip(c, seed, kFirst, kLast);
    EXPECT_NEAR(slip.direction_G().norm(), 1.0, 1e-12);
    EXPECT_GE(slip.direction_G().z(), cos_max - 1e-12) << seed;
    max_sideways = std::max(max_sideways, std::hypot(slip.direction_G().x(), slip.direction_G().y()));
    EXPECT_NEAR(slip.S_G_final().translation().norm(), 0.003, 1e-12);
    EXPECT_TRUE(slip.S_G(slip.end_utime()).isApprox(slip.S_G_final()));
    EXPECT_TRUE(slip.S_G(kLast + 5000000).isApprox(slip.S_G_final()));
    // Rotation-free: the object slides, it does not turn.
    EXPECT_TRUE(slip.S_G_final().linear().isIdentity(1e-15));
    // Mid-recording, 0.3 s long.
    const double fraction = static_cast<double>(slip.start_utime() - kFirst) / (kLast - kFirst);
    EXPECT_GE(fraction, c.start_min_fraction - 1e-6) << seed;
    EXPECT_LE(fraction, c.start_max_fraction + 1e-6) << seed;
    EXPECT_EQ(slip.end_utime() - slip.start_utime(), 300000);
  }
  // The directions spread over the cap, not all on +z.
  EXPECT_GT(max_sideways, 0.8 * std::sin(c.max_tilt_deg * M_PI / 180.0));
}

TEST(ObjectSlip, IsSeeded) {
  const SlipConfig c = Slip(0.005);
  const ObjectSlip a(c, 3, kFirst, kLast), b(c, 3, kFirst, kLast), other(c, 4, kFirst, kLast);
  EXPECT_EQ(a.start_utime(), b.start_utime());
  EXPECT_EQ(a.direction_G(), b.direction_G());
  EXPECT_FALSE(a.direction_G().isApprox(other.direction_G()));
  EXPECT_NE(a.start_utime(), other.start_utime());
}

TEST(ObjectSlip, EasesInAndOutWithoutAJump) {
  const ObjectSlip slip(Slip(0.004), 9, kFirst, kLast);
  const int64_t t0 = slip.start_utime();
  const int64_t t1 = slip.end_utime();
  EXPECT_EQ(slip.Progress(t0), 0.0);
  EXPECT_EQ(slip.Progress(t0 - 1), 0.0);
  EXPECT_NEAR(slip.Progress((t0 + t1) / 2), 0.5, 1e-9);
  EXPECT_EQ(slip.Progress(t1), 1.0);
  // Monotonic, and the speed is zero at both ends (smoothstep): a step of
  // 1 ms moves far less than the mean speed's share.
  double last = 0.0;
  for (int64_t t = t0; t <= t1; t += 1000) {
    const double p = slip.Progress(t);
    EXPECT_GE(p, last);
    last = p;
  }
  const double mean_step = 1000.0 / static_cast<double>(t1 - t0);
  EXPECT_LT(slip.Progress(t0 + 1000), 0.05 * mean_step);
  EXPECT_GT(slip.Progress(t1 - 1000), 1.0 - 0.05 * mean_step);
  EXPECT_GT(slip.Progress((t0 + t1) / 2 + 500) - slip.Progress((t0 + t1) / 2 - 500), mean_step);
}

TEST(ObjectSlip, BadConfigIsRejected) {
  for (double d : {-0.001, 0.05, std::nan("")}) {
    EXPECT_THROW(ObjectSlip(Slip(d), 1, kFirst, kLast), std::invalid_argument) << d;
  }
  SlipConfig c = Slip(0.003);
  c.duration_s = 0.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = Slip(0.003);
  c.start_min_fraction = 0.8;
  c.start_max_fraction = 0.2;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  c = Slip(0.003);
  c.max_tilt_deg = 120.0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace graspfill::synth
