// SPDX-License-Identifier: BSD-3-Clause
// What graspfill's OpenNI2 replay driver (libGraspfillReplay) answers beyond
// OpenNI2's standard properties: shared by the driver and by OpenNI2Source,
// which uses them when the device supports them (a real camera does not).
// Plain C++ (no OpenNI2 header), so that either side can include it.
#pragma once

namespace graspfill::openni2_replay {

/// URI scheme of the replay device: "graspfill-replay:" + path of an LCM log.
constexpr const char* kUriPrefix = "graspfill-replay:";

/// Property ids, in a range OpenNI2 and the PrimeSense drivers leave free
/// ("gf" = 0x6766).
enum PropertyId : int {
  /// Device, float, get/set: playback speed. 1 (default) serves each frame no
  /// earlier than its recorded time after the first; 0 serves the next frame
  /// as soon as the reader waits for one. Either way no frame is skipped:
  /// a frame is made only when the reader asks for one (see the driver).
  kDevicePropertySpeed = 0x67660001,
  /// Device, int, get: frames of the recording not yet served (0 once the
  /// last one went out: the end of the stream).
  kDevicePropertyFramesLeft = 0x67660002,
  /// Stream, double[4] {fx, fy, cx, cy} [pixels], get: the recording's
  /// pinhole intrinsics scaled to the current video mode (exact, where the
  /// field of view gives only fx and fy, rounded to float).
  kStreamPropertyIntrinsics = 0x67660101,
};

}  // namespace graspfill::openni2_replay
