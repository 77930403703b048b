// SPDX-License-Identifier: BSD-3-Clause
// Which LCM channel names graspfill takes (issue 36). LCM refuses a name
// over 63 characters (LCM_MAX_CHANNEL_NAME_LENGTH) on publish, and
// subscribes to a name as a regular expression anchored at both ends:
// "DEPTH(" subscribes to nothing, without a word, and "A.B" also to "AxB".
// graspfill therefore takes 1..63 characters of A-Z a-z 0-9 _ - / only
// (none of them special in a regular expression, so a subscription matches
// the name itself and nothing else), and a different name for each of its
// six channels (a status channel that is also the depth channel would feed
// the module its own status). One check for every way a name comes in: the
// rig config's `channels`, the --*-channel flags of `live` and `replay`.
#pragma once

#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"

namespace graspfill::io {

/// LCM's longest channel name (LCM_MAX_CHANNEL_NAME_LENGTH in lcm/lcm.h).
constexpr size_t kMaxChannelNameLength = 63;

/// "" when `name` is a channel name graspfill takes, else why not: "empty",
/// "300 characters, over LCM's limit of 63", "'(' is not allowed (channel
/// names are A-Z a-z 0-9 _ - / only: LCM subscribes to a name as a regular
/// expression)".
std::string ChannelNameDefect(const std::string& name);

/// The first bad name of the six, in the order depth, gripper_state,
/// object_cloud, status, session, collision_mesh.
struct ChannelNameProblem {
  std::string role;     ///< the channel at fault: "depth", ..., "collision_mesh"
  std::string name;     ///< its name
  std::string defect;   ///< ChannelNameDefect's reason, or "" for a repeat
  std::string same_as;  ///< a repeat: the earlier channel of that name
};

/// Checks every name (ChannelNameDefect), then that no two are the same.
std::optional<ChannelNameProblem> FindChannelNameProblem(const ChannelNames& names);

}  // namespace graspfill::io
