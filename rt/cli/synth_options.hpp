// SPDX-License-Identifier: BSD-3-Clause
// `graspfill synth`'s command line: its usage text, its options and their
// checks (which options go together), for cmd_synth.cpp.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "graspfill/types.hpp"
#include "synth/rig_errors.hpp"
#include "synth/scene.hpp"

namespace graspfill::cli {

extern const char* const kSynthUsage;

struct SynthOptions {
  std::optional<std::string> protocol;
  std::optional<std::string> shape;
  std::optional<std::string> size;
  std::optional<std::string> mesh_path;
  double mesh_scale{1.0};  ///< --mesh-scale
  bool mesh_y_up{false};   ///< --mesh-up y
  bool mesh_transform_given{false};
  std::optional<std::string> grasps;  ///< --grasps S1,S2,...
  std::string claw{"three-finger"};
  std::string claw_mesh_root;  ///< --claw-mesh-root, for a claw file
  std::string grasp{"top-straight"};
  uint64_t seed{1};
  int frames{90};
  bool ideal{false};
  double wall_m{synth::EnvironmentConfig{}.wall_distance_m};
  bool force{false};
  std::string output_dir;
  bool help{false};
  std::optional<int> points;            ///< --protocol only
  synth::RigErrorConfig rig_errors;     ///< logged-pose errors (all off)
  double slip_mm{0.0};                  ///< --slip-mm: the object's slide in the grasp (off)
  double speed_variation{0.0};          ///< --speed-variation (steady turn)
  double mixed_pixel_prob{0.0};         ///< --mixed-pixels (none)
  bool projector_shadow{false};         ///< --projector-shadow
  double dark_patch_share{0.0};         ///< --dark-patches (none)
  double depth_scale{1.0};              ///< --depth-scale (exact)
  double intrinsics_scale{1.0};         ///< --intrinsics-scale (exact)
  double wobble_mm{0.0};                ///< --wobble-mm (none)
  int width{CameraIntrinsics{}.width};  ///< depth image size [pixels]
  int height{CameraIntrinsics{}.height};
  /// Options given that only a recording uses, to refuse them in protocol
  /// mode rather than silently ignore them.
  std::vector<std::string> recording_only_given;
};

/// "WxDxH" in meters, each > 0 and at most 1 m.
/// @throws UsageError
Eigen::Vector3d ParseSize(const std::string& text);

/// The command line, every value and combination checked (not the names
/// of shapes, claws and grasps: the caller's). Stops checking at --help.
/// @throws UsageError
SynthOptions ParseSynthArgs(const Args& args);

}  // namespace graspfill::cli
