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
#include "mesh_option.hpp"
#include "number_parsing.hpp"
#include "threads_option.hpp"
#include "preview.hpp"
#include "unknown_option.hpp"
#include "graspfill/io/output_path.hpp"
#include "graspfill/io/cloud_file.hpp"
#include "graspfill/repair/repairer.hpp"

namespace graspfill::cli {
namespace {

constexpr const char* kUsage =
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

const char* KindName(HoleKind kind) {
  return kind == HoleKind::kClaw ? "claw" : "missing_surface";
}

}  // namespace

namespace {

nlohmann::ordered_json RepairReportJson(const repair::RepairReport& r, size_t points_in,
                                        size_t points_out) {
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

int RunRepair(const Args& args) {
  std::string in, out, preview_dir, mesh_out;
  bool json = false, force = false;
  double scale = 1.0;
  repair::RepairConfig config;
  mesh::PlannerMeshConfig mesh_config;
  bool mesh_flags = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if ((a == "-o" || a == "--output") && has_value) {
      out = args[++i];
    } else if (a == "--preview" && has_value) {
      preview_dir = args[++i];
    } else if (a == "--mesh-out" && has_value) {
      mesh_out = args[++i];
    } else if (a == "--mesh-max-triangles" || a == "--mesh-convex-hull") {
      try {
        ParseMeshFlag(args, &i, &mesh_config, &mesh_flags);
      } catch (const UsageError& e) {
        std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kUsage);
        return 2;
      }
    } else if (a == "--json") {
      json = true;
    } else if (a == "--force") {
      force = true;
    } else if (a == "--mode" && has_value) {
      const std::string m = args[++i];
      if (m == "paper") config.mode = repair::RepairMode::kPaper;
      else if (m == "best") config.mode = repair::RepairMode::kBest;
      else {
        std::fprintf(stderr, "graspfill repair: unknown mode '%s'\n%s", m.c_str(), kUsage);
        return 2;
      }
    } else if (a == "--num-threads" && has_value) {
      try {
        config.num_threads = ParseNumThreads(args[++i]);
      } catch (const UsageError& e) {
        std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kUsage);
        return 2;
      }
    } else if (a == "--scale" && has_value) {
      try {
        scale = ParseDouble("--scale", args[++i], 1e-9, 1e9);
      } catch (const UsageError& e) {
        std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kUsage);
        return 2;
      }
    } else if (a == "--up" && has_value) {
      // X,Y,Z: three strict numbers (no blanks, nothing after them), not all 0.
      const std::string text = args[++i];
      Eigen::Vector3d up;
      try {
        size_t start = 0;
        for (int k = 0; k < 3; ++k) {
          const size_t comma = k < 2 ? text.find(',', start) : text.size();
          if (comma == std::string::npos) throw UsageError("--up '" + text + "': expected X,Y,Z");
          up[k] = ParseDouble("--up", text.substr(start, comma - start), -1e6, 1e6);
          start = comma + 1;
        }
        if (up.norm() == 0.0) throw UsageError("--up '" + text + "': a zero vector has no direction");
      } catch (const UsageError& e) {
        std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kUsage);
        return 2;
      }
      config.up_hint = up.normalized();
    } else if (!a.empty() && a[0] != '-' && in.empty()) {
      in = a;
    } else {
      std::fprintf(stderr, "graspfill repair: %s\n%s", BadOptionText(a, kUsage).c_str(), kUsage);
      return 2;
    }
  }
  if (in.empty() || out.empty()) {
    std::fprintf(stderr, "graspfill repair: need IN.ply and -o OUT.ply\n%s", kUsage);
    return 2;
  }
  try {
    io::CloudFileFormatOf(out);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "graspfill repair: -o %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    CheckMeshOutOption(mesh_out, out, mesh_flags);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "graspfill repair: %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    io::CheckOutputFile(out, force);  // before the repair, not after it
    if (!mesh_out.empty()) io::CheckOutputFile(mesh_out, force);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill repair: %s\n", ErrorText(e).c_str());
    return 1;
  }
  if (!preview_dir.empty() && !PreparePreview(preview_dir, out, force, "repair")) return 1;
  ObjectCloud input = io::ReadCloudFile(in);  // throws with the path
  if (scale != 1.0) {
    for (Eigen::Vector3f& p : input.points_G) p *= static_cast<float>(scale);
  }
  const repair::RepairResult result = repair::Repair(input, config);
  // Beyond the limits the cloud would come back unchanged: most often a
  // cloud in other units, which a planner must not take as repaired.
  if (result.report.status == repair::RepairStatus::kOutOfRange) {
    std::fprintf(stderr,
                 "graspfill repair: '%s': %s; graspfill expects meters and objects a claw can "
                 "hold (--scale 0.001 for a cloud in mm); nothing written\n",
                 in.c_str(), result.report.StatusText().c_str());
    return 1;
  }
  io::WriteCloudFile(out, result.cloud, io::ReplaceIf(force));
  nlohmann::ordered_json report = RepairReportJson(result.report, input.size(), result.cloud.size());
  if (!mesh_out.empty()) {
    try {
      report["mesh"] = BuildAndWriteCollisionMesh(mesh_out, result.cloud, mesh_config, force);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "graspfill repair: collision mesh: %s\n", ErrorText(e).c_str());
      return 1;
    }
  }
  // Written after the cloud: a picture only of what is on the disk.
  const std::string preview =
      preview_dir.empty() ? "" : WritePreview(preview_dir, out, &input, result.cloud, force);
  if (json) {
    std::printf("%s\n", report.dump(2).c_str());
    return 0;
  }
  std::printf("%s: %zu points in, %zu out (%s)\n", in.c_str(), input.size(), result.cloud.size(),
              result.report.StatusText().c_str());
  for (const HoleSummary& h : result.report.holes) {
    std::printf("  %-16s boundary %4d points, %5d points added\n", KindName(h.kind),
                h.boundary_points, h.points_added);
  }
  if (result.report.status == repair::RepairStatus::kRepaired && !result.report.symmetric) {
    std::printf("  no symmetry used: %s\n", result.report.symmetry_reason.c_str());
  }
  double total = 0.0;
  for (const StageTiming& s : result.report.timings) total += s.ms;
  std::printf("  repair took %.1f ms -> %s\n", total, out.c_str());
  if (!preview.empty()) std::printf("  preview -> %s\n", preview.c_str());
  if (!mesh_out.empty()) PrintCollisionMesh(report["mesh"]);
  return 0;
}

}  // namespace graspfill::cli
