// SPDX-License-Identifier: BSD-3-Clause
// Where the fingers of a built-in (procedural) claw touch the object in a
// synthetic scene: each prismatic finger's radial direction, and how far
// the object reaches along it inside the finger's footprint.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/types.hpp"

namespace graspfill::synth {

/// Radial direction of every prismatic finger of a procedural claw, in G.
std::vector<Eigen::Vector3d> FingerDirections(const claw::ClawModel& model);

/// Per direction d: the farthest the object (in G) reaches along d inside
/// that finger's footprint, |p . t| <= width/2 (t = z x d) and z in
/// [0, finger_length]; -inf where no triangle reaches into it.
std::vector<double> FingerTouchRadii(const TriangleMesh& object_G, const std::vector<Eigen::Vector3d>& dirs,
                                     double finger_width_m, double finger_length_m);

}  // namespace graspfill::synth
