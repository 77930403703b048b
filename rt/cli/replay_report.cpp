// SPDX-License-Identifier: BSD-3-Clause
#include "replay_report.hpp"

#include <cstdio>

#include "claw_option.hpp"
#include "evidence_json.hpp"
#include "graspfill/io/messages.hpp"
#include "mesh_option.hpp"
#include "refine_json.hpp"
#include "track_json.hpp"

namespace graspfill::cli {
namespace {

const char* HoleKindName(HoleKind kind) { return kind == HoleKind::kClaw ? "claw" : "missing_surface"; }

double FramesPerSecond(const rt::ReplayResult& r) { return r.stats.frames_integrated / (r.fuse_ms / 1000.0); }

nlohmann::ordered_json GraspsJson(const rt::ReplayResult& r) {
  nlohmann::ordered_json grasps = nlohmann::json::array();
  for (const rt::GraspDelivery& g : r.grasps) {
    if (g.model == rt::DeliveredModel::kOutput) {
      grasps.push_back({{"grasp_id", g.grasp_id}, {"points", g.points}, {"output", g.path}});
    } else {
      grasps.push_back({{"grasp_id", g.grasp_id},
                        {"points", g.points},
                        {"repair", g.RepairStatusText()},
                        {"output", g.path}});
    }
  }
  return grasps;
}

nlohmann::ordered_json RepairJson(const rt::GraspDelivery& output) {
  if (!output.repair) return nullptr;
  const repair::RepairReport& repair = *output.repair;
  nlohmann::ordered_json holes = nlohmann::json::array();
  for (const HoleSummary& h : repair.holes) {
    holes.push_back({{"kind", HoleKindName(h.kind)},
                     {"boundary_points", h.boundary_points},
                     {"points_added", h.points_added},
                     {"unobserved", h.unobserved},
                     {"confidence", h.confidence}});
  }
  return {{"status", repair.StatusText()},
          {"points_added", output.points - output.fused_points},
          {"symmetric", repair.symmetric},
          {"symmetry_reason", repair.symmetry_reason},
          {"top_completion", repair.top_completion},
          {"top_confidence", repair.top_confidence},
          {"holes", holes},
          {"claw_holes_left_open", repair.claw_holes_left_open},
          {"evidence", EvidenceJson(repair.evidence)},
          {"ms", output.repair_ms}};
}

// "repair: ..." of the text report.
void PrintRepair(const rt::GraspDelivery& output) {
  if (!output.repair) {
    std::printf("repair: off (--no-repair)\n");
    return;
  }
  const repair::RepairReport& repair = *output.repair;
  if (repair.status != repair::RepairStatus::kRepaired) {
    std::printf("repair: %s (%.1f ms)\n", repair.StatusText().c_str(), output.repair_ms);
    return;
  }
  int claw_holes = 0, missing_surfaces = 0;
  for (const HoleSummary& h : repair.holes) {
    ++(h.kind == HoleKind::kClaw ? claw_holes : missing_surfaces);
  }
  std::string symmetry = repair.symmetric ? ", top by symmetry" : "";
  if (!repair.symmetric && !repair.symmetry_reason.empty()) {
    symmetry = "; no symmetry: " + repair.symmetry_reason;
  }
  const std::string left_open =
      repair.claw_holes_left_open > 0
          ? ", " + std::to_string(repair.claw_holes_left_open) + " of them left open"
          : "";
  std::printf("repair: %s; %zu points added (%d claw holes%s, %d missing top%s) in %.1f ms\n",
              repair.StatusText().c_str(), output.points - output.fused_points, claw_holes, left_open.c_str(),
              missing_surfaces, symmetry.c_str(), output.repair_ms);
}

}  // namespace

nlohmann::ordered_json ReplayReportJson(const ReplayReport& report) {
  const rt::ReplaySessionConfig& c = report.config;
  const rt::ReplayResult& r = report.result;
  const PipelineStats& stats = r.stats;
  const rt::GraspDelivery& output = r.grasps.back();
  nlohmann::ordered_json j;
  j["log"] = c.log.path;
  j["output"] = c.output_path;
  j["frames_read"] = stats.frames_in;
  j["frames_used"] = stats.frames_integrated;
  j["frames_skipped_no_pose"] = stats.frames_skipped_no_pose;
  j["frames_dropped"] = stats.frames_dropped;
  j["frames_bad"] = stats.frames_bad;
  j["frames_decimated"] = stats.frames_decimated;
  nlohmann::ordered_json by_reason = nlohmann::ordered_json::object();
  for (size_t i = 1; i < kNumFrameSkipReasons; ++i) {
    by_reason[FrameSkipReasonName(static_cast<FrameSkipReason>(i))] = stats.skipped.by_reason[i];
  }
  j["frames_skipped_by_reason"] = by_reason;
  j["bad_events_skipped"] = r.bad_events_skipped;
  j["gripper_states"] = stats.states_in;
  j["gripper_states_rejected"] = stats.states_rejected;
  j["claw"] = {{"name", report.claw.label}, {"from", report.claw.from}};
  j["config"] = report.config_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(report.config_path);
  if (r.session) {
    j["session"] = {{"software_version", r.session->software_version},
                    {"utime", r.session->utime},
                    {"claw", SessionClawLabel(*r.session)},
                    {"descriptions", r.sessions}};
  } else {
    j["session"] = nullptr;
  }
  j["refine"] = RefineJson(report.pipeline);
  j["track_object"] = TrackJson(report.pipeline);
  j["points"] = r.output.size();
  j["grasp_id"] = r.output.grasp_id;
  j["grasps"] = GraspsJson(r);
  j["clock_jumps"] = r.counters.clock_jumps;
  j["frames_skipped_clock_jump"] = r.counters.skipped_clock_jump;
  j["published"] = c.publish ? c.log.channels.object_cloud : "";
  j["preview"] = report.preview_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(report.preview_path);
  j["software_version"] = io::SoftwareVersion();
  j["repair"] = RepairJson(output);
  j["depth_edge_pixels"] = stats.depth_edge_pixels;
  j["timings_ms"] = {{"depth_edges_per_frame", stats.depth_edges.mean_ms()},
                     {"crop_per_frame", stats.crop.mean_ms()},
                     {"mask_per_frame", stats.mask.mean_ms()},
                     {"integrate_per_frame", stats.integrate.mean_ms()},
                     {"visibility_per_frame", stats.visibility.mean_ms()},
                     {"replay_total", r.fuse_ms},
                     {"extract", r.extract_ms},
                     {"repair", output.repair_ms},
                     {"write_ply", output.write_ms},
                     {"publish", output.publish_ms}};
  j["replay_fps"] = FramesPerSecond(r);
  if (report.mesh != nullptr) j["mesh"] = *report.mesh;
  return j;
}

void PrintEarlierGrasps(const rt::ReplayResult& result) {
  for (const rt::GraspDelivery& g : result.grasps) {
    if (g.model != rt::DeliveredModel::kEarlierGrasp || g.step != rt::DeliveryStep::kDelivered) {
      continue;
    }
    std::printf("grasp %lld: %zu points -> %s (repair: %s)\n", static_cast<long long>(g.grasp_id), g.points,
                g.path.c_str(), g.RepairStatusText().c_str());
  }
}

void PrintReplayReport(const ReplayReport& report) {
  const rt::ReplaySessionConfig& c = report.config;
  const rt::ReplayResult& r = report.result;
  const PipelineStats& stats = r.stats;
  std::printf("replayed %s: %lld frames read, %lld used, %lld skipped (no pose), %lld bad\n",
              c.log.path.c_str(), static_cast<long long>(stats.frames_in),
              static_cast<long long>(stats.frames_integrated),
              static_cast<long long>(stats.frames_skipped_no_pose),
              static_cast<long long>(stats.frames_bad + r.bad_events_skipped));
  if (stats.skipped.total() > 0) {
    std::printf("frames not fused, by reason: %s\n", FrameSkipText(stats.skipped).c_str());
  }
  const std::string claw_from = report.claw.from == "default"
                                    ? "default: the recording has no session description"
                                    : "from the " + report.claw.from;
  std::printf("claw: %s (%s)\n", report.claw.label.c_str(), claw_from.c_str());
  std::printf("%s\n", RefineSummary(report.pipeline).c_str());
  if (c.pipeline.track_object.enabled) {
    std::printf("%s\n", TrackSummary(report.pipeline).c_str());
  }
  std::printf("object cloud: %zu points -> %s%s%s\n", r.output.size(), c.output_path.c_str(),
              c.publish ? ", published on " : "", c.publish ? c.log.channels.object_cloud.c_str() : "");
  if (!report.preview_path.empty()) std::printf("preview: %s\n", report.preview_path.c_str());
  std::printf(
      "per frame: crop %.3f ms, claw mask %.3f ms, integrate %.3f ms; "
      "replay %.1f fps; extract %.1f ms\n",
      stats.crop.mean_ms(), stats.mask.mean_ms(), stats.integrate.mean_ms(), FramesPerSecond(r),
      r.extract_ms);
  PrintRepair(r.grasps.back());
  if (report.mesh != nullptr) PrintCollisionMesh(*report.mesh);
}

}  // namespace graspfill::cli
