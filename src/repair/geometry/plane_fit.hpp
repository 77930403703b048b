// SPDX-License-Identifier: BSD-3-Clause
// The repair's one principal-component analysis in 3D: least-squares
// planes (boundary normals, RANSAC refits, a hole's frame, the normals of
// added points) and the smallest principal direction of a scatter (V's
// axis from the side normals). Internal to src/repair.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cstddef>

namespace graspfill::repair::geometry {

/// How a symmetric 3x3 eigenproblem is solved.
enum class EigenSolve {
  /// Eigen's computeDirect, in closed form: a few hundred flops, for the
  /// fits per point (normals, the boundary test). It loses the smallest
  /// eigenvector when the spread spans many orders of magnitude (a stray
  /// point 1e35 m away among the object's).
  kClosedForm,
  /// Eigen's iterative solver: slower, accurate on any input; for the few
  /// fits to many points that strays may be among (RANSAC's refits).
  kIterative,
};

/// Unit eigenvector of the smallest eigenvalue of the symmetric `scatter`;
/// the eigenvalues, increasing, optional.
inline Eigen::Vector3d SmallestEigenvector(const Eigen::Matrix3d& scatter, EigenSolve solve,
                                           Eigen::Vector3d* eigenvalues = nullptr) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  if (solve == EigenSolve::kClosedForm) {
    solver.computeDirect(scatter);
  } else {
    solver.compute(scatter);
  }
  if (eigenvalues != nullptr) *eigenvalues = solver.eigenvalues();
  return solver.eigenvectors().col(0).normalized();
}

/// A least-squares plane: n . p = n . mean.
struct PlaneFit {
  Eigen::Vector3d normal{Eigen::Vector3d::UnitZ()};  ///< unit; sign arbitrary
  Eigen::Vector3d mean{Eigen::Vector3d::Zero()};
  Eigen::Vector3d eigenvalues{Eigen::Vector3d::Zero()};  ///< of the scatter, increasing
  double offset() const { return normal.dot(mean); }
};

/// The least-squares plane of `count` points, `point(i)` giving the i-th
/// as an Eigen::Vector3d (an index list, a kNN row, float points cast):
/// the mean first, then the scatter about it (two passes: no cancellation
/// far from the origin), its smallest principal direction the normal.
/// Fewer than 3 points fix no plane: the normal is then arbitrary, and the
/// eigenvalues say so (the middle one is 0).
template <typename PointAt>
PlaneFit FitPlane(size_t count, const PointAt& point, EigenSolve solve) {
  PlaneFit fit;
  for (size_t i = 0; i < count; ++i) fit.mean += point(i);
  fit.mean /= static_cast<double>(count > 0 ? count : 1);
  // The six distinct sums (the boundary test fits every point's
  // neighbours: this is its inner loop).
  double xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d d = point(i) - fit.mean;
    xx += d.x() * d.x(), xy += d.x() * d.y(), xz += d.x() * d.z();
    yy += d.y() * d.y(), yz += d.y() * d.z(), zz += d.z() * d.z();
  }
  Eigen::Matrix3d scatter;
  scatter << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  fit.normal = SmallestEigenvector(scatter, solve, &fit.eigenvalues);
  return fit;
}

}  // namespace graspfill::repair::geometry
