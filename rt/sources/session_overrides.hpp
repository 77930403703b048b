// SPDX-License-Identifier: BSD-3-Clause
// What a session description changes in the events that follow it: the
// hand-eye calibration used to decode base-frame gripper states, and the
// intrinsics of the depth images; and what a rig config or the command
// line sets over it. Shared by the log and bus sources and the sessions.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt {

/// What a source takes over the session descriptions it reads (a rig
/// config's or the command line's values), and the robot's clock offset.
struct SourceOverrides {
  /// Hand-eye calibration for gripper states given in the base frame
  /// (maps points from B to C).
  Eigen::Isometry3d T_C_B{Eigen::Isometry3d::Identity()};
  /// A session description's T_C_B replaces T_C_B above for the events
  /// after it (false: T_C_B above always, e.g. a rig config's).
  bool T_C_B_from_session{true};
  /// A session description's intrinsics override applies to the depth
  /// images after it; an image of another size is a decode error (false:
  /// `intrinsics` below always).
  bool intrinsics_from_session{true};
  /// The intrinsics override until a session description replaces it (for
  /// good with intrinsics_from_session false, e.g. a rig config's); none =
  /// the images' own.
  std::optional<CameraIntrinsics> intrinsics;
  /// Added to every gripper state's utime [us]: the robot's clock onto the
  /// camera's (a rig config's robot.clock_offset_s).
  int64_t gripper_clock_offset_us{0};
};

/// Gives `frame` the session's intrinsics override `K` (if any): fx, fy,
/// cx, cy replaced when the frame is K's size. Returns false (and says why
/// in *error) when it is not: such a frame is not from the camera the
/// session describes.
inline bool ApplyIntrinsicsOverride(const std::optional<CameraIntrinsics>& K, DepthFrame* frame,
                                    std::string* error) {
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
