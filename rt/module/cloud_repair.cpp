// SPDX-License-Identifier: BSD-3-Clause
#include "module/cloud_repair.hpp"

#include <utility>

namespace graspfill::rt {

repair::RepairConfig GripperFrameRepairConfig(repair::RepairConfig config) {
  config.up_hint = Eigen::Vector3d(0, 0, -1);
  return config;
}

repair::RepairReport RepairObjectCloud(const repair::RepairConfig& config, ObjectCloud* cloud,
                                       const evidence::VisibilityRecord* record) {
  repair::RepairResult result = repair::Repair(*cloud, config, record);
  // Repair copies the input's fields (stamp, pose, fusion timings) into its
  // output and sets its holes, so only the step timings need adding.
  ObjectCloud& repaired = result.cloud;
  for (const StageTiming& step : result.report.timings) {
    repaired.timings.push_back({"repair_" + step.stage, step.ms});
  }
  *cloud = std::move(repaired);
  return std::move(result.report);
}

}  // namespace graspfill::rt
