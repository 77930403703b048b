// SPDX-License-Identifier: BSD-3-Clause
// The frame checks every TSDF of the fusion module makes before it
// integrates: the depth fills the image, and the image keeps its size.
//
// Private to the fusion module (and its internal tool library).
#pragma once

#include <stdexcept>
#include <string>

#include "graspfill/types.hpp"

namespace graspfill::fusion {

/// Throws std::invalid_argument, the message starting with `who`, unless
/// `frame` holds width*height depths and, after the first frame
/// (`frames_before` > 0), has `previous`'s width and height.
inline void CheckFrameSize(const char* who, const DepthFrame& frame, const CameraIntrinsics& previous,
                           int frames_before) {
  const CameraIntrinsics& K = frame.intrinsics;
  if (static_cast<size_t>(K.width) * K.height != frame.depth_m.size()) {
    throw std::invalid_argument(std::string(who) + ": depth size != width*height");
  }
  if (frames_before > 0 && (previous.width != K.width || previous.height != K.height)) {
    throw std::invalid_argument(std::string(who) + ": frame size changed");
  }
}

}  // namespace graspfill::fusion
