// SPDX-License-Identifier: BSD-3-Clause
// The repair's evidence report as JSON, for `replay --json` and the bench.
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

#include "graspfill/repair/repairer.hpp"

namespace graspfill::cli {

inline nlohmann::ordered_json EvidenceJson(const repair::EvidenceReport& e) {
  nlohmann::ordered_json j;
  j["used"] = e.used;
  j["ignored_reason"] = e.ignored_reason;
  j["key_frames"] = e.key_frames;
  j["observed_free_share"] = e.observed_free_share;
  j["mirror_free_share"] = std::isnan(e.mirror_free_share) ? nlohmann::ordered_json(nullptr)
                                                           : nlohmann::ordered_json(e.mirror_free_share);
  j["mirror_plane_drop_mm"] = 1000.0 * e.mirror_plane_drop_m;
  j["mirror_lift_mm"] = 1000.0 * e.mirror_lift_m;
  j["rejected_free"] = e.rejected_free;
  j["moved_out_of_claw"] = e.moved_out_of_claw;
  j["rejected_in_claw"] = e.rejected_in_claw;
  j["top"] = e.top;
  j["top_above_wall_mm"] = 1000.0 * e.top_above_wall_m;
  j["top_points_added"] = e.top_points_added;
  j["safe_bound_voxels"] = e.safe_bound_voxels;
  return j;
}

}  // namespace graspfill::cli
