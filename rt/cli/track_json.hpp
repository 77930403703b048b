// SPDX-License-Identifier: BSD-3-Clause
// The object tracking's report (refine/object_tracker.hpp) as JSON and as
// one line of text, for `replay`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "graspfill/pipeline/pipeline.hpp"

namespace graspfill::cli {

inline nlohmann::ordered_json TrackJson(const Pipeline& pipeline) {
  const refine::ObjectTracker& tracker = pipeline.tracker();
  const PipelineStats& stats = pipeline.stats();
  const refine::TrackStats& t = stats.tracking;
  nlohmann::ordered_json j;
  j["enabled"] = tracker.config().enabled;
  if (!tracker.config().enabled) return j;
  const double n = t.frames_tracked > 0 ? static_cast<double>(t.frames_tracked) : 1.0;
  j["frames_tracked"] = t.frames_tracked;
  j["frames_before_a_model"] = t.frames_no_model;
  j["frames_rejected"] = {{"total", t.rejected()},
                          {"too_few_points", t.rejected_too_few_points},
                          {"not_converged", t.rejected_not_converged},
                          {"jump", t.rejected_jump}};
  j["model_updates"] = t.model_updates;
  j["mean_residual_rms_mm"] = 1000.0 * t.rms_sum_m / n;
  j["mean_iterations"] = t.iterations / n;
  j["mean_points_matched"] = t.matches / n;
  j["pose_updates"] = t.pose_updates;
  j["frames_underconstrained"] = t.frames_underconstrained;
  j["max_step_mm"] = 1000.0 * t.max_step_m;
  // Where the object is in G now: p_G = S_G * p (the cloud's frame is the
  // object's as first seen).
  const Eigen::Isometry3d S = pipeline.ObjectPose();
  nlohmann::ordered_json rows = nlohmann::json::array();
  for (int row = 0; row < 4; ++row) rows.push_back({S(row, 0), S(row, 1), S(row, 2), S(row, 3)});
  j["object_pose"] = {
      {"S_G", rows},
      {"translation_mm", 1000.0 * S.translation().norm()},
      {"rotation_deg", Eigen::AngleAxisd(S.linear()).angle() * 180.0 / 3.14159265358979323846}};
  j["ms_per_frame"] = stats.track_time.mean_ms();
  return j;
}

inline std::string TrackSummary(const Pipeline& pipeline) {
  const refine::ObjectTracker& tracker = pipeline.tracker();
  if (!tracker.config().enabled) return "object tracking: off (--track-object turns it on)";
  const refine::TrackStats& t = pipeline.stats().tracking;
  const Eigen::Isometry3d S = pipeline.ObjectPose();
  char line[400];
  std::snprintf(line, sizeof(line),
                "object tracking: %lld frames tracked, %lld rejected (too few points %lld, not "
                "converged %lld, jump %lld); the object moved %.2f mm, %.2f deg in G; %.3f ms a "
                "frame",
                static_cast<long long>(t.frames_tracked), static_cast<long long>(t.rejected()),
                static_cast<long long>(t.rejected_too_few_points),
                static_cast<long long>(t.rejected_not_converged), static_cast<long long>(t.rejected_jump),
                1000.0 * S.translation().norm(),
                Eigen::AngleAxisd(S.linear()).angle() * 180.0 / 3.14159265358979323846,
                pipeline.stats().track_time.mean_ms());
  return line;
}

}  // namespace graspfill::cli
