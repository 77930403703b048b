// SPDX-License-Identifier: BSD-3-Clause
// Rejects the pixels on depth edges before integration: where two
// neighbouring returns differ by more than any surface the sensor can see
// explains, the ray straddles an edge, and its depth may be a mix of the
// two sides (a "flying pixel" between an object and what lies behind it).
// Fused, such pixels leave points floating free of the object and a fringe
// on its rims; both sides of the jump are dropped, since either may be the
// mixed one.
//
// The bound: neighbouring pixels subtend 1/f rad, so a surface seen at
// incidence theta changes depth by about z tan(theta) / f between them; a
// structured-light or time-of-flight sensor returns little beyond
// kDepthEdgeMaxIncidenceDeg (Nguyen et al. 2012's angular noise term grows
// without bound towards 90 deg), and two noisy samples differ by up to
// kDepthEdgeNoiseM more.
#pragma once

#include <cstdint>
#include <vector>

#include "graspfill/fusion/workspace_crop.hpp"
#include "graspfill/types.hpp"

namespace graspfill::fusion {

/// The steepest surface the sensor returns depth from [deg between the ray
/// and the normal].
inline constexpr double kDepthEdgeMaxIncidenceDeg = 80.0;
/// Two samples of one surface differ by up to this more [m]: 3 sigma of
/// their difference for a Kinect-v1-like sensor at 0.5 m (sigma ~1.2 mm).
inline constexpr double kDepthEdgeNoiseM = 0.005;

/// Zeroes every pixel of `frame` inside `roi` whose depth differs from a
/// 4-neighbour's (both with a return, 0 = none) by more than
/// z tan(kDepthEdgeMaxIncidenceDeg) / f + kDepthEdgeNoiseM, z the nearer of
/// the two. Pixels outside `roi` are neither changed nor read. `marks` is
/// scratch, kept by the caller between frames (allocates only when the
/// frame grows). Returns the number of pixels zeroed.
/// @throws std::invalid_argument when the depth buffer does not hold
///   width x height pixels.
int RejectDepthEdges(const PixelRect& roi, DepthFrame* frame, std::vector<uint8_t>* marks);

}  // namespace graspfill::fusion
