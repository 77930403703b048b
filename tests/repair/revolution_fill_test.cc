// SPDX-License-Identifier: BSD-3-Clause
// The surface of revolution (src/repair/revolution_fill.hpp): right where
// the object is one (a sphere and a spheroid whose top is cut off), no
// surface where nothing closes it (a cylinder, a cup that widens to its
// mouth), samples only where the cloud leaves a hole, and the surface's
// own normals.
#include "revolution_fill.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace graspfill::repair {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Points on the surface r(z)^2 = a + b z + c z^2 about (x0, y0), for z in
// [z0, z1], about `step_m` apart, with Gaussian radial noise.
PointList OnProfile(double x0, double y0, double a, double b, double c, double z0, double z1, double step_m,
                    double noise_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  PointList out;
  for (double z = z0; z <= z1; z += step_m) {
    const double r2 = a + b * z + c * z * z;
    if (r2 <= 0.0) continue;
    const double r = std::sqrt(r2);
    const int n = static_cast<int>(std::ceil(2.0 * kPi * r / step_m));
    for (int k = 0; k < n; ++k) {
      const double t = 2.0 * kPi * k / n, rr = r + noise(rng);
      out.emplace_back(static_cast<float>(x0 + rr * std::cos(t)), static_cast<float>(y0 + rr * std::sin(t)),
                       static_cast<float>(z));
    }
  }
  return out;
}

TEST(RevolutionFill, SphereWithItsTopCutOffClosesAtItsPole) {
  // R = 40 mm about (3, -2, 0) mm, seen up to z = 25 mm.
  const double R = 0.04;
  const PointList cloud = OnProfile(0.003, -0.002, R * R, 0.0, -1.0, -R, 0.025, 0.001, 0.0003, 1);
  const std::optional<Revolution> s = FitRevolution(cloud, 0.025, 0.04);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->x0, 0.003, 3e-4);
  EXPECT_NEAR(s->y0, -0.002, 3e-4);
  EXPECT_NEAR(s->pole_z, R, 1e-3);
  EXPECT_LT(s->rms_m, 6e-4);
  const RevolutionSamples samples = SampleRevolution(*s, -R, 0.001, 0.005, cloud);
  ASSERT_FALSE(samples.points_V.empty());
  // Every sample on the sphere, and none on the seen body, which has no
  // hole a spacing wide (but near the far pole, where the cloud's rings of
  // constant z step far along the surface).
  for (const Eigen::Vector3f& p : samples.points_V) {
    EXPECT_NEAR((p.cast<double>() - Eigen::Vector3d(0.003, -0.002, 0.0)).norm(), R, 1e-3);
    EXPECT_TRUE(p.z() > 0.024f || p.z() < -0.03f) << p.transpose();
  }
  // The whole cap is covered: each true cap point within 1.5 mm of one.
  const PointList cap = OnProfile(0.003, -0.002, R * R, 0.0, -1.0, 0.027, R, 0.002, 0.0, 2);
  const NeighborIndex index(samples.points_V);
  for (const Eigen::Vector3f& p : cap) EXPECT_TRUE(index.AnyWithin(p, 0.0015)) << p.transpose();
  // The cap's middle, over 5 mm from the seen rim, is a hole; the samples
  // beside the rim are not.
  ASSERT_EQ(samples.in_hole.size(), samples.points_V.size());
  for (size_t i = 0; i < samples.points_V.size(); ++i) {
    const Eigen::Vector3f& p = samples.points_V[i];
    if (p.z() > 0.034f) {
      EXPECT_TRUE(samples.in_hole[i]) << p.transpose();
    }
    if (p.z() > 0.0f && p.z() < 0.026f) {
      EXPECT_FALSE(samples.in_hole[i]) << p.transpose();
    }
  }
}

TEST(RevolutionFill, SamplesLeftAreThoseNoTakenPointComesWithinASpacingOf) {
  // The definition, by brute force: with nothing taken, every sample; with
  // a scattered cloud taken (off the surface, with a gap, all around the
  // axis and up to the pole), exactly those samples with no taken point,
  // moved radially onto the surface, within a spacing; and in_hole where
  // none lies within the hole's width either.
  const double R = 0.04, spacing = 0.0012, hole = 0.0036;
  const Revolution s{0.003, -0.002, R * R, 0.0, -1.0, R, 0.0};
  const RevolutionSamples all = SampleRevolution(s, -0.9 * R, spacing, hole, {});
  ASSERT_GT(all.points_V.size(), 1000u);
  for (char h : all.in_hole) EXPECT_TRUE(h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  PointList taken;
  while (taken.size() < 6000) {
    const Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
    if (d.norm() < 0.1 || d.norm() > 1.0) continue;
    const Eigen::Vector3d p = Eigen::Vector3d(0.003, -0.002, 0.0) + (R + 0.001 * unit(rng)) * d.normalized();
    if (std::abs(p.z() - 0.01) < 0.004) continue;  // a band left open
    taken.push_back(p.cast<float>());
  }
  PointList on_surface;
  for (const Eigen::Vector3f& p : taken) {
    const Eigen::Vector2d d(p.x() - s.x0, p.y() - s.y0);
    const double r2 = s.RadiusSquared(p.z());
    if (r2 <= 0.0) continue;
    const Eigen::Vector2d q = Eigen::Vector2d(s.x0, s.y0) + d.normalized() * std::sqrt(r2);
    on_surface.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()), p.z());
  }
  const auto within = [&](const Eigen::Vector3f& a, double radius) {
    for (const Eigen::Vector3f& b : on_surface) {
      if ((a.cast<double>() - b.cast<double>()).squaredNorm() <= radius * radius) return true;
    }
    return false;
  };
  PointList expected;
  std::vector<char> expected_hole;
  for (const Eigen::Vector3f& p : all.points_V) {
    if (within(p, spacing)) continue;
    expected.push_back(p);
    expected_hole.push_back(!within(p, hole));
  }
  const RevolutionSamples left = SampleRevolution(s, -0.9 * R, spacing, hole, taken);
  ASSERT_GT(expected.size(), 100u);
  ASSERT_LT(expected.size(), all.points_V.size() / 2);
  ASSERT_EQ(left.points_V.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(left.points_V[i], expected[i]) << i;
    EXPECT_EQ(left.in_hole[i], expected_hole[i]) << i;
  }
}

TEST(RevolutionFill, NormalsPointOutOfTheSurface) {
  // A sphere's: along the radius, at the pole too; a spheroid's: its
  // gradient, which is not radial off the equator and the poles.
  const Revolution sphere{0.003, -0.002, 1.6e-3, 0.0, -1.0, 0.04, 0.0};
  const Eigen::Vector3d centre(0.003, -0.002, 0.0);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.6, 0, 0.8),
                                   Eigen::Vector3d(0, -0.8, -0.6), Eigen::Vector3d(0, 0, 1)}) {
    const Eigen::Vector3f n = sphere.Normal((centre + 0.04 * d).cast<float>());
    EXPECT_NEAR(n.cast<double>().dot(d), 1.0, 1e-6) << d.transpose();
  }
  // r^2 = 900 mm^2 - 0.5625 z^2 at z = 20 mm: r^2 = 675 mm^2; the normal
  // is along (r, 0.5625 z) = (25.98, 11.25), 23.4 degrees above the
  // horizontal, not the point's own 37.6 degrees.
  const Revolution spheroid{0.0, 0.0, 9e-4, 0.0, -0.5625, 0.04, 0.0};
  const Eigen::Vector3f n =
      spheroid.Normal(Eigen::Vector3f(static_cast<float>(std::sqrt(6.75e-4)), 0.0f, 0.02f));
  EXPECT_NEAR(std::atan2(n.z(), n.x()) * 180.0 / kPi, std::atan2(11.25, std::sqrt(675.0)) * 180.0 / kPi,
              1e-3);
  EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
  // On the axis of a cylinder (no gradient): zero, for the caller to estimate.
  const Revolution cylinder{0.0, 0.0, 9e-4, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(cylinder.Normal(Eigen::Vector3f(0.0f, 0.0f, 0.05f)), Eigen::Vector3f::Zero());
}

TEST(RevolutionFill, SpheroidKeepsItsProfile) {
  // r^2 = 900 mm^2 - 0.5625 z^2: semi-axes 30 mm (r) and 40 mm (z).
  const PointList cloud = OnProfile(0.0, 0.0, 9e-4, 0.0, -0.5625, -0.04, 0.02, 0.001, 0.0002, 3);
  const std::optional<Revolution> s = FitRevolution(cloud, 0.02, 0.04);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->c, -0.5625, 0.05);
  EXPECT_NEAR(s->pole_z, 0.04, 1.5e-3);
}

TEST(RevolutionFill, NothingClosesACylinderOrACupThatWidens) {
  // A can's wall: r = 30 mm at every height; no pole.
  const PointList can = OnProfile(0.0, 0.0, 9e-4, 0.0, 0.0, 0.0, 0.1, 0.001, 0.0002, 4);
  EXPECT_FALSE(FitRevolution(can, 0.1, 0.05).has_value());
  // A cup widening towards its mouth at the top: r from 25 to 30 mm.
  const double b = (0.03 * 0.03 - 0.025 * 0.025) / 0.08;
  const PointList cup = OnProfile(0.0, 0.0, 0.025 * 0.025, b, 0.0, 0.0, 0.08, 0.001, 0.0002, 5);
  EXPECT_FALSE(FitRevolution(cup, 0.08, 0.04).has_value());
  // A pole past the reach (a sphere seen only to a third of its height).
  const PointList low_cap = OnProfile(0.0, 0.0, 1.6e-3, 0.0, -1.0, -0.04, -0.015, 0.001, 0.0002, 6);
  EXPECT_FALSE(FitRevolution(low_cap, -0.015, 0.02).has_value());
}

TEST(RevolutionFill, TooFewPointsOrNoneGiveNoSurface) {
  EXPECT_FALSE(FitRevolution({}, 0.0, 0.1).has_value());
  PointList few(10, Eigen::Vector3f(0.01f, 0.0f, 0.0f));
  EXPECT_FALSE(FitRevolution(few, 0.0, 0.1).has_value());
}

}  // namespace
}  // namespace graspfill::repair
