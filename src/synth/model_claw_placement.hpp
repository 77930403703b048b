// SPDX-License-Identifier: BSD-3-Clause
// How a description or URDF claw (any ClawModel, not the procedural claws
// whose fingers can be measured directly) holds the object in a synthetic
// scene. The rule (docs/claws.md, "Claws from URDF"):
//  - orientation and the position across G's z axis as for the built-in
//    claws (scene.hpp): the object's top towards the palm, the contact
//    point on G's z axis, the oblique grasp's tilt;
//  - height: the object's top `min_palm_gap_m` from the palm face (z = 0),
//    or as much farther (2 mm steps) as the open claw needs to clear it;
//  - opening: the claw closes from its open end (FindOpeningRange) until it
//    first touches the object, and holds at the last opening before that
//    (to 1/4096 of the range): a sample of the claw's surface (one point
//    per ~2 mm^2) may not lie inside the object (ray parity).
// The claw keeps its own geometry: the grasp's contact height and finger
// lengthening of the built-in rule do not apply.
#pragma once

#include <Eigen/Geometry>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/types.hpp"

namespace graspfill::synth {

struct ModelClawHold {
  Eigen::Isometry3d T_G_O{Eigen::Isometry3d::Identity()};  ///< object in G
  double palm_gap_m{0.0};                                  ///< palm face to the object's top
  double opening{0.0};                                     ///< in the claw's own units
};

/// `R_G_O` the object's orientation in G and `axis_offset_xy` its position
/// across the z axis (both from the built-in rule). `object_O` must be
/// closed. Throws std::invalid_argument when the object does not fit in the
/// open claw or the closed claw does not touch it.
ModelClawHold HoldInModelClaw(const claw::ClawModel& claw, const TriangleMesh& object_O,
                              const Eigen::Matrix3d& R_G_O, const Eigen::Vector2d& axis_offset_xy,
                              double min_palm_gap_m);

}  // namespace graspfill::synth
