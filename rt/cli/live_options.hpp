// SPDX-License-Identifier: BSD-3-Clause
// `graspfill live`'s flags and rig config, parsed into the session's
// configs (the command then only picks the claw and wires, cmd_live.cpp).
#pragma once

#include <optional>
#include <string>

#include "commands.hpp"
#include "config/rig_config.hpp"
#include "graspfill/repair/repairer.hpp"
#include "module/live_session.hpp"
#include "sources/camera_source.hpp"

namespace graspfill::cli {

/// live's usage text (the camera's flags follow it: kCameraUsage).
extern const char* const kLiveUsage;

/// What the flags and the rig config ask of a live session.
struct LiveOptions {
  rt::CameraSource::Config camera;
  rt::LiveSessionConfig session;
  repair::RepairConfig repair;
  std::optional<std::string> claw_spec;  ///< --claw or the config's; resolved to a file or built-in
  std::string mesh_root;
  bool depth_from_lcm{false};
  bool force{false};
  bool help{false};  ///< --help: nothing else was parsed after it
  /// What the config fixes over a session description's box and voxel.
  bool voxel_given{false};
  bool workspace_given{false};
  double sdf_trunc_voxels{4.0};
};

/// The rig config `rig` (LoadConfigOption's), then the flags over it.
/// @throws UsageError for a bad flag or value.
LiveOptions ParseLiveOptions(const Args& args, const std::optional<rt::RigConfig>& rig);

}  // namespace graspfill::cli
