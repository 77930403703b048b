// SPDX-License-Identifier: BSD-3-Clause
// The hole repair applied to the object cloud a planner receives: the one
// step `graspfill replay` and the live RepairStage share, so that both
// publish the same message for the same fused cloud.
#pragma once

#include "graspfill/repair/repairer.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt {

/// `config` for fused clouds in the gripper frame G: the up hint. The palm
/// is at z = 0 and the object at z > 0, so the top the camera never sees
/// faces the palm, along -z. A hint only: it fixes the sign of the repair's
/// frame and narrows its search.
repair::RepairConfig GripperFrameRepairConfig(repair::RepairConfig config = {});

/// Repairs `*cloud` in place. The fused points stay first and unchanged
/// (normals included), the added ones follow (provenance surface /
/// symmetry, normals estimated when the input had them); the report's holes
/// replace cloud->holes and its step timings are appended to cloud->timings
/// as "repair_" + step, so that LCM subscribers see both. Returns the
/// report. Throws what repair::Repair throws (std::invalid_argument on a
/// non-finite point or a bad config), leaving `*cloud` untouched.
/// `record` (optional): what the camera saw, in G (Pipeline::visibility()).
repair::RepairReport RepairObjectCloud(const repair::RepairConfig& config, ObjectCloud* cloud,
                                       const evidence::VisibilityRecord* record = nullptr);

}  // namespace graspfill::rt
