// SPDX-License-Identifier: BSD-3-Clause
// Kasa's algebraic circle fit, shared by the rim curve (the centre of an
// arc) and the claw fills' widest-point test (each slab's centre).
// Internal to src/repair.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <optional>

namespace graspfill::repair::geometry {

/// x^2 + y^2 + D x + E y + F = 0 in least squares over the points added;
/// the centre is (-D/2, -E/2). For an arc it is the arc's own centre, not
/// a point in front of it.
class CircleFit {
 public:
  void Add(double x, double y) {
    const Eigen::Vector3d row(x, y, 1.0);
    ata_ += row * row.transpose();
    atb_ -= row * (x * x + y * y);
  }
  /// nullopt when the points fix no circle (fewer than 3, or collinear).
  std::optional<Eigen::Vector2d> Centre() const {
    const Eigen::Vector3d def = ata_.ldlt().solve(atb_);
    if (!def.allFinite() || !(ata_(2, 2) >= 3.0)) return std::nullopt;
    return Eigen::Vector2d(-0.5 * def.x(), -0.5 * def.y());
  }

 private:
  Eigen::Matrix3d ata_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb_ = Eigen::Vector3d::Zero();
};

}  // namespace graspfill::repair::geometry
