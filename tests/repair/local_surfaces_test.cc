// SPDX-License-Identifier: BSD-3-Clause
// The local surfaces' normals (src/repair/local_surfaces.hpp): a height
// field's on the side of its frame's n, and a quadric's gradient, on a
// tilted plane and a sphere whose normals are known.
#include "local_surfaces.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace graspfill::repair::fill {
namespace {

TEST(LocalSurfaces, AHeightFieldsNormalIsItsGradientsOnNsSide) {
  // w = 0.5 u - 0.25 v over a frame turned about x: the normal is
  // n - 0.5 e1 + 0.25 e2, normalized, wherever it is asked.
  HoleFrame frame;
  frame.origin = Eigen::Vector3d(0.01, 0.02, 0.03);
  frame.e1 = Eigen::Vector3d::UnitX();
  frame.e2 = Eigen::Vector3d(0.0, std::cos(0.3), std::sin(0.3));
  frame.n = frame.e1.cross(frame.e2);
  PointList points;
  std::vector<int> support;
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j) {
      const double u = 0.002 * i, v = 0.002 * j;
      support.push_back(static_cast<int>(points.size()));
      points.push_back(frame.World(u, v, 0.5 * u - 0.25 * v).cast<float>());
    }
  }
  HeightField field;
  ASSERT_TRUE(FitHeightField(points, support, frame, 2, 3, 0.001, &field));
  const Eigen::Vector3d expected = (frame.n - 0.5 * frame.e1 + 0.25 * frame.e2).normalized();
  for (const auto& [u, v] : {std::pair{0.0, 0.0}, std::pair{0.015, -0.01}, std::pair{-0.02, 0.02}}) {
    EXPECT_GT(field.Normal(u, v).dot(expected), 1.0 - 1e-9) << u << " " << v;
  }
}

TEST(LocalSurfaces, AQuadricsGradientIsASpheresRadius) {
  // A sphere of 30 mm about (5, -5, 10) mm, its upper half.
  const Eigen::Vector3d centre(0.005, -0.005, 0.01);
  PointList points;
  std::vector<int> support;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 40; ++j) {
      const double polar = 0.05 + 1.4 * i / 20.0, azimuth = 2.0 * M_PI * j / 40.0;
      const Eigen::Vector3d d(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                              std::cos(polar));
      support.push_back(static_cast<int>(points.size()));
      points.push_back((centre + 0.03 * d).cast<float>());
    }
  }
  Quadric quadric;
  ASSERT_TRUE(FitQuadric(points, support, std::vector<double>(support.size(), 1.0), 6, 0.0001, &quadric));
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d radial = (p.cast<double>() - centre).normalized();
    EXPECT_GT(std::abs(quadric.Gradient(p.cast<double>()).normalized().dot(radial)), 1.0 - 1e-6);
  }
}

}  // namespace
}  // namespace graspfill::repair::fill
