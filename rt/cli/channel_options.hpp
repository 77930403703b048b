// SPDX-License-Identifier: BSD-3-Clause
// The --*-channel flags of `live` and `replay`: once the config and the
// flags have set them, the six names are checked as LCM takes them
// (graspfill/io/channel_names.hpp), so that a name LCM would subscribe to
// as a broken regular expression is a usage error, not a deaf module.
#pragma once

#include <optional>
#include <string>

#include "graspfill/io/channel_names.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {

/// The flag that sets a channel ("depth" -> "--depth-channel").
inline std::string ChannelFlag(const std::string& role) {
  if (role == "gripper_state") return "--gripper-channel";
  if (role == "object_cloud") return "--cloud-channel";
  if (role == "collision_mesh") return "--mesh-channel";
  return "--" + role + "-channel";
}

/// @throws UsageError naming the flag and the name: "--depth-channel
///   'DEPTH(': '(' is not allowed (...)", "the depth and status channels are
///   both 'X' (each channel needs its own name)".
inline void CheckChannelOptions(const io::ChannelNames& channels) {
  const std::optional<io::ChannelNameProblem> problem = io::FindChannelNameProblem(channels);
  if (!problem) return;
  if (!problem->defect.empty()) {
    throw UsageError(ChannelFlag(problem->role) + " '" + problem->name + "': " + problem->defect);
  }
  throw UsageError("the " + problem->same_as + " and " + problem->role + " channels are both '" +
                   problem->name + "' (each channel needs its own name)");
}

}  // namespace graspfill::cli
