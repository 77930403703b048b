// SPDX-License-Identifier: BSD-3-Clause
#include "axis_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "geometry/plane_fit.hpp"

namespace graspfill::repair {

void AxisRefineConfig::Validate() const {
  const auto require = [](bool ok, const char* message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(side_band_rad > 0.0 && side_band_rad < M_PI / 2,
          "AxisRefineConfig.side_band_rad must be in (0, pi/2)");
  require(min_side_fraction >= 0.0 && min_side_fraction <= 1.0,
          "AxisRefineConfig.min_side_fraction must be in [0, 1]");
  require(max_change_rad > 0.0 && max_change_rad <= M_PI / 2,
          "AxisRefineConfig.max_change_rad must be in (0, pi/2]");
  require(straight_wall_share >= 0.0 && straight_wall_share <= 1.0 / 3.0,
          "AxisRefineConfig.straight_wall_share must be in [0, 1/3]");
  require(straight_max_change_rad > 0.0 && straight_max_change_rad <= M_PI / 2,
          "AxisRefineConfig.straight_max_change_rad must be in (0, pi/2]");
  require(iterations >= 1 && iterations <= 100, "AxisRefineConfig.iterations must be in [1, 100]");
}

AxisRefinement RefineAxis(const std::vector<Eigen::Vector3f>& normals, const Eigen::Vector3d& initial_axis,
                          const AxisRefineConfig& config) {
  config.Validate();
  if (!initial_axis.allFinite() || std::abs(initial_axis.norm() - 1.0) > 1e-6) {
    throw std::invalid_argument("RefineAxis: the initial axis must be a unit vector");
  }
  AxisRefinement result;
  result.axis = initial_axis;
  if (!config.enabled) {
    result.note = "disabled";
    return result;
  }
  const double max_dot = std::sin(config.side_band_rad);  // |n . axis| of a side point
  Eigen::Vector3d axis = initial_axis;
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
  for (int it = 0; it < config.iterations; ++it) {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    size_t sides = 0;
    for (const Eigen::Vector3f& nf : normals) {
      const Eigen::Vector3d n = nf.cast<double>();
      if (n.squaredNorm() < 0.5 || std::abs(n.dot(axis)) > max_dot) continue;
      scatter.noalias() += n * n.transpose();
      ++sides;
    }
    if (static_cast<double>(sides) < config.min_side_fraction * static_cast<double>(normals.size()) ||
        sides < 3) {
      result.note = "too few side points (" + std::to_string(sides) + ")";
      return result;
    }
    Eigen::Vector3d next =
        geometry::SmallestEigenvector(scatter, geometry::EigenSolve::kClosedForm, &eigenvalues);
    if (next.dot(initial_axis) < 0.0) next = -next;
    axis = next;
  }
  const double change = std::acos(std::min(1.0, axis.dot(initial_axis)));
  result.smallest_share = eigenvalues.sum() > 0.0 ? eigenvalues(0) / eigenvalues.sum() : 1.0;
  const bool straight = result.smallest_share <= config.straight_wall_share;
  if (change > (straight ? config.straight_max_change_rad : config.max_change_rad)) {
    result.note =
        "refined axis moved " + std::to_string(change * 180.0 / M_PI) + " degrees: kept the initial one";
    return result;
  }
  result.axis = axis;
  result.refined = true;
  result.change_rad = change;
  return result;
}

VirtualFrame WithAxis(const VirtualFrame& frame, const Eigen::Vector3d& axis, const PointList& cloud) {
  const Eigen::Vector3d z = axis.normalized();
  const Eigen::Vector3d old_x = frame.T_in_V.linear().col(0);
  Eigen::Vector3d x = old_x - z * z.dot(old_x);
  if (x.norm() < 1e-6) x = z.unitOrthogonal();
  x.normalize();
  VirtualFrame out;
  out.T_in_V.linear().col(0) = x;
  out.T_in_V.linear().col(1) = z.cross(x);
  out.T_in_V.linear().col(2) = z;
  out.T_in_V.translation() = frame.T_in_V.translation();
  if (cloud.empty()) return out;
  double z_min = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3f& p : cloud) {
    z_min = std::min(z_min, z.dot(p.cast<double>() - out.T_in_V.translation()));
  }
  out.T_in_V.translation() += z_min * z;
  const Eigen::Isometry3d T_V_in = out.T_in_V.inverse();
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& p : cloud) box.extend(T_V_in * p.cast<double>());
  out.min_V = box.min().cast<float>();
  out.max_V = box.max().cast<float>();
  return out;
}

}  // namespace graspfill::repair
