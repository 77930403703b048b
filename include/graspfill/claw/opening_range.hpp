// SPDX-License-Identifier: BSD-3-Clause
// Which openings move a claw, and which end of them is open: the opening's
// units differ between claws (meters of gap for the built-ins and the Franka
// description, a 0..1 closure for the Robotiq and URDF claws), so code that
// closes any claw on an object (synth) asks the model.
#pragma once

#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw {

struct OpeningRange {
  double open{0.0};    ///< the opening with the fingers farthest out
  double closed{0.0};  ///< the other end
};

/// From the smallest to the largest opening at which an opening-driven
/// joint (gain != 0, finite limits) reaches a limit; `open` is the end at
/// which the links those joints move lie farther (mean over their vertices)
/// from G's z axis. Throws std::invalid_argument naming the claw when no
/// joint follows the opening.
OpeningRange FindOpeningRange(const ClawModel& model);

}  // namespace graspfill::claw
