// SPDX-License-Identifier: BSD-3-Clause
// What a session description may ask of its receiver: the limits that the
// rig config file (rt/config/rig_config_checks.hpp) holds the same fields to, one
// definition for both, so that a value the bus or a log gives is never
// taken when the config file would refuse it (io::SessionWithinLimits in
// messages.hpp checks a description against them).
#pragma once

namespace graspfill::io {

/// Every coordinate of the workspace box in G [m]: -kMaxWorkspaceM..
/// kMaxWorkspaceM (a held object is centimetres across).
constexpr double kMaxWorkspaceM = 2.0;
/// The TSDF voxel edge [m]: below 0.5 mm a 10 cm object's volume takes
/// gigabytes; from ~1.5 cm up a 5-10 cm object is a few voxels across and
/// its cloud comes out empty.
constexpr double kMinVoxelM = 0.0005;
constexpr double kMaxVoxelM = 0.01;
/// Every coordinate of the hand-eye T_C_B's translation [m].
constexpr double kMaxHandEyeTranslationM = 10.0;

}  // namespace graspfill::io
