// SPDX-License-Identifier: BSD-3-Clause
// The OpenNI2 camera's command-line options, shared by `live` and
// `oni-record`: video mode, intrinsics override, replay speed and the log
// read alongside the device (docs/openni2.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "module/live_session.hpp"
#include "number_parsing.hpp"
#include "sources/camera_source.hpp"

namespace graspfill::cli {

constexpr const char* kCameraUsage =
    "  --width N / --height N / --fps N   the device's video mode (default: its own;\n"
    "                        a mode it lacks is an error listing those it has)\n"
    "  --depth-units mm|100um  units asked of the device (default mm)\n"
    "  --fx F / --fy F / --cx C / --cy C  pinhole intrinsics [pixels] instead of the device's\n"
    "  --fov-deg H,V         field of view [degrees]: fx, fy from it (--fx/--fy win)\n"
    "  --replay-speed S      graspfill-replay devices: 1 (default) the recorded rate, 0 as\n"
    "                        fast as read; no frame is ever skipped\n"
    "  --gripper-log LOG     gripper states and session description from LOG, in time order\n"
    "                        with the device's frames (a graspfill-replay:LOG device reads\n"
    "                        its own LOG); an .oni's timestamps are moved onto LOG's clock\n";

/// Parses args[*i] (and its value) if it is a camera option into *config,
/// advancing *i past what it took. Returns false for any other option.
/// @throws UsageError on a bad value.
inline bool ParseCameraOption(const std::vector<std::string>& args, size_t* i,
                              rt::CameraSource::Config* config) {
  const std::string& a = args[*i];
  const bool is_option = a == "--width" || a == "--height" || a == "--fps" || a == "--depth-units" ||
                         a == "--fx" || a == "--fy" || a == "--cx" || a == "--cy" || a == "--fov-deg" ||
                         a == "--replay-speed" || a == "--gripper-log";
  if (!is_option) return false;
  if (*i + 1 >= args.size()) throw UsageError(a + " needs a value");
  const std::string& v = args[++*i];
  rt::OpenNI2Source::Config& d = config->device;
  rt::OpenNI2Source::IntrinsicsOverride& K = d.intrinsics;
  constexpr double kMaxPixels = 100000.0;
  if (a == "--width")
    d.width = ParseInteger<int>(a, v, 1, 16384);
  else if (a == "--height")
    d.height = ParseInteger<int>(a, v, 1, 16384);
  else if (a == "--fps")
    d.fps = ParseInteger<int>(a, v, 1, 1000);
  else if (a == "--depth-units") {
    if (v == "mm")
      d.depth_mode = rt::OpenNI2Source::DepthMode::k1mm;
    else if (v == "100um")
      d.depth_mode = rt::OpenNI2Source::DepthMode::k100um;
    else
      throw UsageError("--depth-units must be mm or 100um, not '" + v + "'");
  } else if (a == "--fx")
    K.fx = ParseDouble(a, v, 1.0, kMaxPixels, "pixels");
  else if (a == "--fy")
    K.fy = ParseDouble(a, v, 1.0, kMaxPixels, "pixels");
  else if (a == "--cx")
    K.cx = ParseDouble(a, v, -kMaxPixels, kMaxPixels, "pixels");
  else if (a == "--cy")
    K.cy = ParseDouble(a, v, -kMaxPixels, kMaxPixels, "pixels");
  else if (a == "--fov-deg") {
    const size_t comma = v.find(',');
    if (comma == std::string::npos) throw UsageError("--fov-deg wants H,V, not '" + v + "'");
    K.hfov_deg = ParseDouble(a, v.substr(0, comma), 1.0, 179.0, "degrees");
    K.vfov_deg = ParseDouble(a, v.substr(comma + 1), 1.0, 179.0, "degrees");
  } else if (a == "--replay-speed")
    d.replay_speed = static_cast<float>(ParseDouble(a, v, 0.0, 100.0));
  else
    config->log = v;  // --gripper-log
  return true;
}

/// Makes `source` wait, before each frame it asks of a device that hands
/// them out as fast as asked (a recording, a replay device at speed 0),
/// until the live session's frame queue of `capacity` has room: the module
/// drops the oldest frame when its queue is full. Gives up waiting after 2 s
/// (a frame waiting for gripper states that never come), then goes on.
inline void GateFramesOnRoom(rt::CameraSource* source, const rt::LiveSession& live, int capacity) {
  source->SetFrameGate([&live, capacity] {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    for (;;) {
      const io::ModuleStatus s = live.Status();
      // Frames pushed but not yet fused, skipped or dropped (a frame pending
      // in the pipeline counts: at most the newest one while states flow).
      const int64_t queued = s.frames_in - s.frames_used - s.frames_skipped - s.frames_dropped;
      if (queued < capacity || std::chrono::steady_clock::now() > give_up) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
}

}  // namespace graspfill::cli
