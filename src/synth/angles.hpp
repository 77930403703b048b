// SPDX-License-Identifier: BSD-3-Clause
// Degrees to radians, once for the synth library (its configs are in degrees).
#pragma once

#include <cmath>

namespace graspfill::synth {

inline constexpr double kDegToRad = M_PI / 180.0;

}  // namespace graspfill::synth
