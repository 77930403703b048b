// SPDX-License-Identifier: BSD-3-Clause
// Value types shared by the steps of the hole repair (Cui, Zhang & Wang,
// Sensors 2021, section 2; see ../shared/paper/). Each step is its own unit
// in src/repair/ with its own header; the Repairer chains them.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::repair {

/// Points in meters, in the frame the caller says (input frame or V).
using PointList = std::vector<Eigen::Vector3f>;

/// An ordered chain of hole-boundary points (paper 2.2.2): indices into the
/// cloud the boundary points were detected in, in linking order.
struct BoundaryLine {
  std::vector<int> indices;
  bool closed{false};  ///< the last point links back to the first
};

/// The virtual camera frame V (paper 2.2.3 A). +z is orthogonal to the
/// plane of the missing surface's boundary and points towards the missing
/// surface (so the missing top is at the largest z); x and y follow the
/// edges of the 2D bounding box of the cloud projected on that plane.
struct VirtualFrame {
  Eigen::Isometry3d T_in_V{Eigen::Isometry3d::Identity()};  ///< V -> input
  Eigen::Vector3f min_V{0, 0, 0};                           ///< bounding box of the cloud in V [m]
  Eigen::Vector3f max_V{0, 0, 0};
};

/// One hole's boundary after classification (paper 2.2.3 B) and, once
/// completed (2.2.4), closed. Points in V, in order along the boundary.
struct HoleBoundary {
  HoleKind kind{HoleKind::kClaw};
  PointList points_V;
  /// For each point of points_V, the index in the input cloud it was
  /// detected at, or -1 for points added by the completion.
  std::vector<int> source_indices;
  bool closed{false};
};

}  // namespace graspfill::repair
