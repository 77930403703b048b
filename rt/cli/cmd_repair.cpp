// SPDX-License-Identifier: BSD-3-Clause
// graspfill repair IN.ply -o OUT.{ply,pcd}: fills the claw holes and the unseen
// top of an object cloud; every input point is kept, added points carry
// their provenance (PLY property or PCD field `provenance`: 0 observed,
// 1 surface, 2 symmetry).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "error_text.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/repair/repairer.hpp"
#include "mesh_option.hpp"
#include "number_parsing.hpp"
#include "option_walk.hpp"
#include "preview.hpp"
#include "threads_option.hpp"
#include "unknown_option.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kRepairUsage =
    "usage: graspfill repair IN.ply -o OUT.{ply,pcd} [--mode paper|best] [--up X,Y,Z] [--preview DIR]\n"
    "                               [--mesh-out FILE.{ply,stl,obj} [--mesh-max-triangles N]\n"
    "                               [--mesh-convex-hull]] [--scale S] [--num-threads N] [--json]\n"
    "                               [--force]\n"
    "  IN.ply     unorganized cloud in meters, any pose, normals optional\n"
    "  --scale    multiply IN's coordinates by S first (0.001: a cloud in mm)\n"
    "  --mode     paper: the method as published; best (default): graspfill's\n"
    "  -o         the repaired cloud, PLY or PCD by its extension\n"
    "  --up       optional hint of the direction to the missing top, input frame\n"
    "  --json     print the holes found and the time of every step as JSON\n"
    "  --preview  also a picture of the cloud before and after: DIR/<OUT's stem>.png\n"
    "  --mesh-out the repaired cloud's collision mesh for a planner (and its deviation):\n"
    "             watertight, holding the cloud, at most --mesh-max-triangles N triangles\n"
    "             (default 5000), or with --mesh-convex-hull the cloud's convex hull\n"
    "  --force    overwrite OUT (and the preview) if it exists\n"
    "  --num-threads  OpenMP threads of the repair, 0..1024 (default 1; 0: OpenMP's own count)\n"
    "example: graspfill repair scan.ply -o repaired.pcd --up 0,0,1 --mesh-out hull.stl\n";

const char* KindName(HoleKind kind) { return kind == HoleKind::kClaw ? "claw" : "missing_surface"; }

}  // namespace

namespace {

nlohmann::ordered_json RepairReportJson(const repair::RepairReport& r, size_t points_in, size_t points_out) {
  nlohmann::ordered_json j;
  j["status"] = r.StatusText();
  j["points_in"] = points_in;
  j["points_out"] = points_out;
  j["symmetric"] = r.symmetric;
  if (!r.symmetric) j["symmetry_reason"] = r.symmetry_reason;
  j["top_completion"] = r.top_completion;
  j["top_confidence"] = r.top_confidence;
  if (r.status == repair::RepairStatus::kRepaired) {
    // The virtual frame's +z (towards the missing top) in the input frame.
    const Eigen::Vector3d z = r.frame.T_in_V.linear().col(2);
    j["up_axis"] = {z.x(), z.y(), z.z()};
  }
  j["outliers_ignored"] = r.outliers_ignored;
  j["boundary_points"] = r.boundary_points;
  j["boundary_lines"] = r.boundary_lines;
  j["claw_holes_left_open"] = r.claw_holes_left_open;
  j["holes"] = nlohmann::json::array();
  for (const HoleSummary& h : r.holes) {
    j["holes"].push_back({{"kind", KindName(h.kind)},
                          {"boundary_points", h.boundary_points},
                          {"box_min", {h.box_min_G.x(), h.box_min_G.y(), h.box_min_G.z()}},
                          {"box_max", {h.box_max_G.x(), h.box_max_G.y(), h.box_max_G.z()}},
                          {"points_added", h.points_added},
                          {"unobserved", h.unobserved},
                          {"confidence", h.confidence}});
  }
  nlohmann::ordered_json t;
  for (const StageTiming& s : r.timings) t[s.stage] = s.ms;
  j["timings_ms"] = t;
  return j;
}

}  // namespace

namespace {

struct RepairOptions {
  bool help{false};
  std::string in, out, preview_dir, mesh_out;
  bool json{false};
  bool force{false};
  double scale{1.0};
  repair::RepairConfig config;
  mesh::PlannerMeshConfig mesh_config;
  bool mesh_flags{false};  // --mesh-max-triangles or --mesh-convex-hull given
};

// --up X,Y,Z: three strict numbers (no blanks, nothing after them), not all 0.
Eigen::Vector3d ParseUp(const std::string& text) {
  Eigen::Vector3d up;
  size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = k < 2 ? text.find(',', start) : text.size();
    if (comma == std::string::npos) throw UsageError("--up '" + text + "': expected X,Y,Z");
    up[k] = ParseDouble("--up", text.substr(start, comma - start), -1e6, 1e6);
    start = comma + 1;
  }
  if (up.norm() == 0.0) throw UsageError("--up '" + text + "': a zero vector has no direction");
  return up;
}

// The command line, up to --help if given.
// @throws UsageError on an unknown option, a missing or bad value.
RepairOptions ParseRepairArgs(const Args& args) {
  RepairOptions o;
  o.help = ForEachOption(args, [&](const std::string& a, bool has_value, size_t* i) {
    if ((a == "-o" || a == "--output") && has_value) {
      o.out = args[++*i];
    } else if (a == "--preview" && has_value) {
      o.preview_dir = args[++*i];
    } else if (a == "--mesh-out" && has_value) {
      o.mesh_out = args[++*i];
    } else if (a == "--mesh-max-triangles" || a == "--mesh-convex-hull") {
      ParseMeshFlag(args, i, &o.mesh_config, &o.mesh_flags);
    } else if (a == "--json") {
      o.json = true;
    } else if (a == "--force") {
      o.force = true;
    } else if (a == "--mode" && has_value) {
      const std::string m = args[++*i];
      if (m == "paper")
        o.config.mode = repair::RepairMode::kPaper;
      else if (m == "best")
        o.config.mode = repair::RepairMode::kBest;
      else
        throw UsageError("unknown mode '" + m + "'");
    } else if (a == "--num-threads" && has_value) {
      o.config.num_threads = ParseNumThreads(args[++*i]);
    } else if (a == "--scale" && has_value) {
      o.scale = ParseDouble("--scale", args[++*i], 1e-9, 1e9);
    } else if (a == "--up" && has_value) {
      o.config.up_hint = ParseUp(args[++*i]).normalized();
    } else if (!a.empty() && a[0] != '-' && o.in.empty()) {
      o.in = a;
    } else {
      throw BadOption(a, kRepairUsage);
    }
  });
  if (o.help) return o;
  if (o.in.empty() || o.out.empty()) throw UsageError("need IN.ply and -o OUT.ply");
  try {
    io::CloudFileFormatOf(o.out);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("-o ") + e.what());
  }
  CheckMeshOutOption(o.mesh_out, o.out, o.mesh_flags);
  return o;
}

// The report in words: the holes, the symmetry, the time, where it went.
void PrintRepairSummary(const RepairOptions& o, size_t points_in, const repair::RepairResult& result,
                        const std::string& preview, const nlohmann::ordered_json& report) {
  std::printf("%s: %zu points in, %zu out (%s)\n", o.in.c_str(), points_in, result.cloud.size(),
              result.report.StatusText().c_str());
  for (const HoleSummary& h : result.report.holes) {
    std::printf("  %-16s boundary %4d points, %5d points added\n", KindName(h.kind), h.boundary_points,
                h.points_added);
  }
  if (result.report.status == repair::RepairStatus::kRepaired && !result.report.symmetric) {
    std::printf("  no symmetry used: %s\n", result.report.symmetry_reason.c_str());
  }
  double total = 0.0;
  for (const StageTiming& s : result.report.timings) total += s.ms;
  std::printf("  repair took %.1f ms -> %s\n", total, o.out.c_str());
  if (!preview.empty()) std::printf("  preview -> %s\n", preview.c_str());
  if (!o.mesh_out.empty()) PrintCollisionMesh(report.at("mesh"));
}

// Repairs, writes the cloud (and mesh, preview) and reports; the outputs
// were checked before.
int RepairAndWrite(const RepairOptions& o) {
  ObjectCloud input = io::ReadCloudFile(o.in);  // throws with the path
  if (o.scale != 1.0) {
    for (Eigen::Vector3f& p : input.points_G) p *= static_cast<float>(o.scale);
  }
  const repair::RepairResult result = repair::Repair(input, o.config);
  // Beyond the limits the cloud would come back unchanged: most often a
  // cloud in other units, which a planner must not take as repaired.
  if (result.report.status == repair::RepairStatus::kOutOfRange) {
    std::fprintf(stderr,
                 "graspfill repair: '%s': %s; graspfill expects meters and objects a claw can "
                 "hold (--scale 0.001 for a cloud in mm); nothing written\n",
                 o.in.c_str(), result.report.StatusText().c_str());
    return 1;
  }
  io::WriteCloudFile(o.out, result.cloud, io::ReplaceIf(o.force));
  nlohmann::ordered_json report = RepairReportJson(result.report, input.size(), result.cloud.size());
  if (!o.mesh_out.empty()) {
    try {
      report["mesh"] = BuildAndWriteCollisionMesh(o.mesh_out, result.cloud, o.mesh_config, o.force);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill repair: collision mesh: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }
  // Written after the cloud: a picture only of what is on the disk.
  const std::string preview =
      o.preview_dir.empty() ? "" : WritePreview(o.preview_dir, o.out, &input, result.cloud, o.force);
  if (o.json) {
    std::printf("%s\n", report.dump(2).c_str());
    return 0;
  }
  PrintRepairSummary(o, input.size(), result, preview, report);
  return 0;
}

}  // namespace

int RunRepair(const Args& args) {
  RepairOptions o;
  try {
    o = ParseRepairArgs(args);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kRepairUsage);
    return 2;
  }
  if (o.help) {
    std::fputs(kRepairUsage, stdout);
    return 0;
  }
  try {
    io::CheckOutputFile(o.out, o.force);  // before the repair, not after it
    if (!o.mesh_out.empty()) io::CheckOutputFile(o.mesh_out, o.force);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill repair: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (!o.preview_dir.empty() && !PreparePreview(o.preview_dir, o.out, o.force, "repair")) return 1;
  return RepairAndWrite(o);
}

}  // namespace graspfill::cli
