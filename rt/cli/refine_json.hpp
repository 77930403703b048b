// SPDX-License-Identifier: BSD-3-Clause
// The pose refinement's report (refine/pose_refiner.hpp) as JSON and as one
// line of text, for `replay` and `bench`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "graspfill/pipeline/pipeline.hpp"

namespace graspfill::cli {

inline nlohmann::ordered_json RefineJson(const Pipeline& pipeline) {
  const refine::PoseRefiner& refiner = pipeline.refiner();
  const PipelineStats& stats = pipeline.stats();
  const refine::RefineStats& r = stats.refine;
  nlohmann::ordered_json j;
  j["enabled"] = refiner.config().enabled;
  if (!refiner.config().enabled) return j;
  const double n = r.frames_refined > 0 ? static_cast<double>(r.frames_refined) : 1.0;
  j["frames_refined"] = r.frames_refined;
  j["frames_rejected"] = {{"total", r.rejected()},
                          {"claw_not_seen", r.rejected_claw_not_seen},
                          {"not_converged", r.rejected_not_converged},
                          {"jump", r.rejected_jump}};
  j["mean_correction_of_logged_pose"] = {{"mm", 1000.0 * r.correction_sum_m / n},
                                         {"deg", r.correction_sum_deg / n}};
  const double tracked = r.frames_tracked > 0 ? static_cast<double>(r.frames_tracked) : 1.0;
  j["mean_correction_beyond_hand_eye"] = {{"frames", r.frames_tracked},
                                          {"frames_below_min_correction", r.frames_at_prediction},
                                          {"mm", 1000.0 * r.residual_sum_m / tracked},
                                          {"deg", r.residual_sum_deg / tracked},
                                          {"max_mm", 1000.0 * r.max_residual_m}};
  j["mean_residual_rms_mm"] = 1000.0 * r.rms_sum_m / n;
  j["mean_iterations"] = r.iterations / n;
  j["mean_claw_points_matched"] = r.matches / n;
  // T_C_G ~= H * T_C_G_logged: the constant part (hand-eye error, and what
  // a clock offset does to a steady turn, unless clock_offset is applied), in C.
  const Eigen::Isometry3d H = refiner.HandEyeCorrection();
  const Eigen::AngleAxisd aa(H.linear());
  const Eigen::Vector3d centre = refiner.claw_centre_C();
  nlohmann::ordered_json rows = nlohmann::json::array();
  for (int row = 0; row < 4; ++row) {
    rows.push_back({H(row, 0), H(row, 1), H(row, 2), H(row, 3)});
  }
  j["hand_eye_correction"] = {{"frames", refiner.hand_eye_samples()},
                              {"H_C", rows},
                              {"rotation_deg", aa.angle() * 180.0 / 3.14159265358979323846},
                              {"translation_mm", 1000.0 * H.translation().norm()},
                              {"shift_at_claw_mm", 1000.0 * (H * centre - centre).norm()},
                              {"claw_centre_C", {centre.x(), centre.y(), centre.z()}}};
  // The clock offset (RefineConfig::clock_*): from how the corrections
  // follow the motion's rate; null where not estimable (a steady turn).
  const refine::ClockOffsetEstimate& clock = refiner.clock_offset();
  const bool estimable = std::isfinite(clock.stderr_s);
  j["clock_offset"] = {{"applied", clock.applied},
                       {"offset_ms", estimable ? nlohmann::ordered_json(1000.0 * clock.offset_s)
                                               : nlohmann::ordered_json(nullptr)},
                       {"stderr_ms", estimable ? nlohmann::ordered_json(1000.0 * clock.stderr_s)
                                               : nlohmann::ordered_json(nullptr)},
                       {"frames", clock.frames},
                       {"jump_frames_in_fit", r.clock_only_samples}};
  // The depth's scale from the claw's size: the sensor's depth is `factor`
  // times the true one; `applied` is what the frames were divided by
  // (RefineConfig::apply_depth_scale). null until estimable.
  const refine::DepthScaleEstimate& scale = refiner.depth_scale();
  const bool scale_known = std::isfinite(scale.stderr_);
  const auto known = [&](double v) {
    return scale_known ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
  };
  j["depth_scale"] = {{"factor", known(scale.factor)},
                      {"stderr", known(scale.stderr_)},
                      {"error_percent", known(100.0 * (scale.factor - 1.0))},
                      {"frames", scale.frames},
                      {"applied", scale.applied},
                      {"changes", scale.changes},
                      {"ms_per_frame", stats.depth_scale.mean_ms() + stats.depth_rescale.mean_ms()}};
  j["ms_per_frame"] = stats.refine_time.mean_ms();
  return j;
}

inline std::string RefineSummary(const Pipeline& pipeline) {
  const refine::PoseRefiner& refiner = pipeline.refiner();
  if (!refiner.config().enabled) return "pose refinement: off (--no-refine)";
  const refine::RefineStats& r = pipeline.stats().refine;
  const Eigen::Isometry3d H = refiner.HandEyeCorrection();
  const Eigen::Vector3d centre = refiner.claw_centre_C();
  const refine::ClockOffsetEstimate& c = refiner.clock_offset();
  char clock[96] = "not estimable";
  if (std::isfinite(c.stderr_s)) {
    std::snprintf(clock, sizeof(clock), "%.1f +- %.1f ms%s", 1000.0 * c.offset_s, 1000.0 * c.stderr_s,
                  c.applied ? " (applied)" : " (not applied)");
  }
  const refine::DepthScaleEstimate& s = refiner.depth_scale();
  char scale[96] = "not estimable yet";
  if (std::isfinite(s.stderr_)) {
    std::snprintf(scale, sizeof(scale), "%+.2f +- %.2f%%%s", 100.0 * (s.factor - 1.0), 100.0 * s.stderr_,
                  s.applied != 1.0 ? " (applied)" : " (not applied)");
  }
  char line[560];
  std::snprintf(line, sizeof(line),
                "pose refinement: %lld frames refined, %lld rejected (claw not seen %lld, not "
                "converged %lld, jump %lld); hand-eye correction %.2f mm at the claw, %.3f deg; "
                "per frame beyond it %.2f mm; clock offset %s; depth scale error %s; %.3f ms a frame",
                static_cast<long long>(r.frames_refined), static_cast<long long>(r.rejected()),
                static_cast<long long>(r.rejected_claw_not_seen),
                static_cast<long long>(r.rejected_not_converged), static_cast<long long>(r.rejected_jump),
                1000.0 * (H * centre - centre).norm(),
                Eigen::AngleAxisd(H.linear()).angle() * 180.0 / 3.14159265358979323846,
                1000.0 * r.residual_sum_m / std::max<double>(1.0, static_cast<double>(r.frames_tracked)),
                clock, scale, pipeline.stats().refine_time.mean_ms());
  return line;
}

}  // namespace graspfill::cli
