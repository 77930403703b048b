// SPDX-License-Identifier: BSD-3-Clause
// What a session description changes in the events that follow it: the
// hand-eye calibration used to decode base-frame gripper states, and the
// intrinsics of the depth images. Shared by the log and bus sources.
#pragma once

#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt {

/// Gives `frame` the session's intrinsics override `K` (if any): fx, fy,
/// cx, cy replaced when the frame is K's size. Returns false (and says why
/// in *error) when it is not: such a frame is not from the camera the
/// session describes.
inline bool ApplyIntrinsicsOverride(const std::optional<CameraIntrinsics>& K,
                                    DepthFrame* frame, std::string* error) {
  if (!K) return true;
  if (frame->intrinsics.width != K->width || frame->intrinsics.height != K->height) {
    if (error != nullptr) {
      *error = "depth image of " + std::to_string(frame->intrinsics.width) + "x" +
               std::to_string(frame->intrinsics.height) +
               " pixels, but the intrinsics override (the session description's or the "
               "rig config's) is for " +
               std::to_string(K->width) + "x" + std::to_string(K->height) + " images";
    }
    return false;
  }
  frame->intrinsics = *K;
  return true;
}

}  // namespace graspfill::rt
