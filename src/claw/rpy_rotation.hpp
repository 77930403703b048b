// SPDX-License-Identifier: BSD-3-Clause
// The rotation of an "rpy" (claw descriptions and URDF claw configs, as a
// URDF <origin>): fixed-axis roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll).
#pragma once

#include <Eigen/Geometry>

namespace graspfill::claw {

inline Eigen::Matrix3d RotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace graspfill::claw
