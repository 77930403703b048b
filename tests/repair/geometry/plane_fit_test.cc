// SPDX-License-Identifier: BSD-3-Clause
#include "geometry/plane_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "graspfill/core/random.hpp"

namespace graspfill::repair::geometry {
namespace {

// Points on the plane n . p = d, spread over +-5 cm around `centre`, with
// `noise_m` of uniform noise along n.
std::vector<Eigen::Vector3d> PlanePatch(const Eigen::Vector3d& n, const Eigen::Vector3d& centre,
                                        double noise_m, int count, uint64_t seed) {
  Rng rng(seed);
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    points.push_back(centre + 0.1 * (rng.Uniform() - 0.5) * u + 0.1 * (rng.Uniform() - 0.5) * v +
                     noise_m * (2.0 * rng.Uniform() - 1.0) * n);
  }
  return points;
}

TEST(PlaneFit, ATiltedPlaneFarFromTheOriginComesBackWithItsOffset) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Vector3d centre(40.0, -25.0, 12.0);
  const std::vector<Eigen::Vector3d> points = PlanePatch(n, centre, 1e-3, 500, 1);
  const PlaneFit fit = FitPlane(
      points.size(), [&](size_t i) { return points[i]; }, EigenSolve::kClosedForm);
  EXPECT_NEAR(std::abs(fit.normal.dot(n)), 1.0, 1e-6);
  EXPECT_NEAR(fit.normal.norm(), 1.0, 1e-12);
  // The plane passes through the patch: the centre lies on it to within
  // the noise's mean (+-1 mm uniform, 500 points).
  EXPECT_NEAR(fit.normal.dot(centre) - fit.offset(), 0.0, 1e-4);
  EXPECT_NEAR((fit.mean - centre).norm(), 0.0, 0.01);
  // Eigenvalues increasing: the spread along n (uniform, +-1 mm) is by far
  // the smallest.
  EXPECT_LE(fit.eigenvalues(0), fit.eigenvalues(1));
  EXPECT_LE(fit.eigenvalues(1), fit.eigenvalues(2));
  EXPECT_LT(fit.eigenvalues(0), 1e-3 * fit.eigenvalues(1));
}

TEST(PlaneFit, CollinearPointsSayTheyFixNoPlane) {
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 20; ++i) line.emplace_back(0.01 * i, 0.02 * i, -0.005 * i);
  const PlaneFit fit = FitPlane(
      line.size(), [&](size_t i) { return line[i]; }, EigenSolve::kClosedForm);
  EXPECT_LT(fit.eigenvalues(1), 1e-12 * fit.eigenvalues(2));
  // No point: no scatter, a finite answer.
  const PlaneFit none = FitPlane(
      0, [&](size_t i) { return line[i]; }, EigenSolve::kIterative);
  EXPECT_TRUE(none.normal.allFinite());
  EXPECT_EQ(none.eigenvalues.sum(), 0.0);
}

// A stray point 1e30 m away among a flat patch (as the fuzzer found): the
// closed form's smallest eigenvector is lost in the rounding of the
// stray's scatter; the iterative solver still tells the patch's flat
// direction from the stray's. (Why RANSAC's refits iterate.)
TEST(PlaneFit, TheIterativeSolverKeepsThePlaneBesideAnAbsurdStray) {
  std::vector<Eigen::Vector3d> points =
      PlanePatch(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), 0.0, 200, 2);
  points.emplace_back(1e30, 0.0, 0.0);  // along the patch: the plane z = 0 holds it too
  const auto at = [&](size_t i) { return points[i]; };
  const PlaneFit iterative = FitPlane(points.size(), at, EigenSolve::kIterative);
  EXPECT_NEAR(std::abs(iterative.normal.z()), 1.0, 1e-9);
  const PlaneFit closed = FitPlane(points.size(), at, EigenSolve::kClosedForm);
  EXPECT_LT(std::abs(closed.normal.z()), 0.99);
}

TEST(PlaneFit, SmallestEigenvectorOfAScatterIsItsLeastSpreadDirection) {
  // Unit vectors around a cone's side, all nearly square to `axis`: the
  // axis is the direction they spread least along.
  const Eigen::Vector3d axis = Eigen::Vector3d(-0.2, 0.1, 1.0).normalized();
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 36; ++i) {
    const double a = i * M_PI / 18.0;
    const Eigen::Vector3d n = (std::cos(a) * u + std::sin(a) * v + 0.05 * axis).normalized();
    scatter += n * n.transpose();
  }
  Eigen::Vector3d eigenvalues;
  const Eigen::Vector3d found = SmallestEigenvector(scatter, EigenSolve::kClosedForm, &eigenvalues);
  EXPECT_NEAR(std::abs(found.dot(axis)), 1.0, 1e-9);
  EXPECT_NEAR(eigenvalues.sum(), scatter.trace(), 1e-9);
  EXPECT_LT(eigenvalues(0), 0.01 * eigenvalues(1));
}

}  // namespace
}  // namespace graspfill::repair::geometry
