// SPDX-License-Identifier: BSD-3-Clause
// --mesh-out FILE.{ply,stl,obj} (replay, repair): the planner's collision
// mesh of the command's model (mesh/planner_mesh.hpp: at most
// --mesh-max-triangles triangles, watertight, holding the cloud within its
// stated deviation; --mesh-convex-hull for the hull), written after the
// cloud, with its deviation from the cloud printed and in --json.
#pragma once

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "commands.hpp"
#include "graspfill/io/mesh_export.hpp"
#include "graspfill/mesh/mesh_deviation.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"
#include "graspfill/mesh/planner_mesh.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {

/// Reads --mesh-max-triangles N or --mesh-convex-hull at args[*i] into
/// *config (advancing *i past a value); *given: one was. False for any other
/// argument.
/// @throws UsageError on a missing or bad value.
inline bool ParseMeshFlag(const Args& args, size_t* i, mesh::PlannerMeshConfig* config, bool* given) {
  const std::string& a = args[*i];
  if (a == "--mesh-convex-hull") {
    config->convex_hull = true;
  } else if (a == "--mesh-max-triangles") {
    if (*i + 1 >= args.size()) throw UsageError(a + " needs a value");
    config->max_triangles =
        ParseInteger<int>(a, args[++*i], mesh::kMinPlannerTriangles, mesh::kMaxPlannerTriangles);
  } else {
    return false;
  }
  *given = true;
  return true;
}

/// Checks --mesh-out's path once the command line is parsed: a known
/// extension, not the cloud's own output; and that the mesh's flags
/// (`mesh_flags`) come with it.
/// @throws UsageError saying which.
inline void CheckMeshOutOption(const std::string& mesh_path, const std::string& cloud_path,
                               bool mesh_flags = false) {
  if (mesh_path.empty()) {
    if (mesh_flags) throw UsageError("--mesh-max-triangles and --mesh-convex-hull need --mesh-out");
    return;
  }
  if (!io::MeshFormatOf(mesh_path)) {
    throw UsageError("--mesh-out '" + mesh_path + "': unknown extension (use .ply, .stl or .obj)");
  }
  std::error_code ec;
  if (mesh_path == cloud_path || std::filesystem::equivalent(mesh_path, cloud_path, ec)) {
    throw UsageError("--mesh-out '" + mesh_path + "' is the cloud's output (-o) too");
  }
}

/// Writes `m` (the planner mesh of `cloud`, made in `build_ms`) to `path`
/// (replacing a file there only with `force`) and measures it against the
/// cloud. `channel`: where it was published ("" = not).
/// @return the report (--json's "mesh"; PrintCollisionMesh prints it).
/// @throws std::exception from the write.
inline nlohmann::ordered_json WriteCollisionMesh(const std::string& path, const ObjectCloud& cloud,
                                                 const mesh::PlannerMesh& m,
                                                 const mesh::PlannerMeshConfig& config, double build_ms,
                                                 const std::string& channel, bool force) {
  io::WriteMesh(path, m.mesh, io::ReplaceIf(force));
  const mesh::MeshDeviation d = mesh::MeasureDeviation(m.mesh, cloud);
  auto mm = [](double meters) { return meters * 1e3; };
  nlohmann::ordered_json j;
  j["output"] = path;
  j["kind"] = m.kind == CollisionMeshKind::kConvexHull ? "convex_hull" : "decimated";
  j["method"] = mesh::PlannerMeshMethodName(m.method);
  j["vertices"] = m.mesh.vertices.size();
  j["triangles"] = m.mesh.triangles.size();
  j["max_triangles"] = config.max_triangles;
  j["dense_triangles"] = m.dense_triangles;
  j["closed"] = mesh::IsClosedOriented(m.mesh);
  j["watertight"] = m.watertight;
  j["cell_mm"] = mm(m.cell_m);
  // The stated deviation: the farthest cloud point outside the mesh.
  j["deviation_mm"] = mm(m.outside.max_m);
  j["outside_mm"] = {
      {"p99", mm(m.outside.p99_m)}, {"max", mm(m.outside.max_m)}, {"points", m.outside.points_outside}};
  j["fallback"] = m.fallback_reason;
  j["surface_to_cloud_mm"] = {{"p50", mm(d.surface_to_cloud_p50_m)},
                              {"p95", mm(d.surface_to_cloud_p95_m)},
                              {"max", mm(d.surface_to_cloud_max_m)}};
  j["cloud_to_surface_mm"] = {{"p50", mm(d.cloud_to_surface_p50_m)},
                              {"p95", mm(d.cloud_to_surface_p95_m)},
                              {"max", mm(d.cloud_to_surface_max_m)}};
  j["build_ms"] = build_ms;
  j["published"] = channel;
  return j;
}

/// Builds the planner mesh of `cloud` (not published: `repair` has no bus)
/// and writes it (WriteCollisionMesh).
/// @throws std::exception from the mesh (a cloud too small) or the write.
inline nlohmann::ordered_json BuildAndWriteCollisionMesh(const std::string& path, const ObjectCloud& cloud,
                                                         const mesh::PlannerMeshConfig& config, bool force) {
  const auto t0 = std::chrono::steady_clock::now();
  const mesh::PlannerMesh m = mesh::BuildPlannerMesh(cloud, config);
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return WriteCollisionMesh(path, cloud, m, config, build_ms, "", force);
}

/// Prints WriteCollisionMesh's report in three lines (a fourth for a fallback).
inline void PrintCollisionMesh(const nlohmann::ordered_json& j) {
  const auto& out = j["surface_to_cloud_mm"];
  const auto& in = j["cloud_to_surface_mm"];
  const auto& outside = j["outside_mm"];
  std::printf("collision mesh: %zu vertices, %zu triangles (%s, %s, %s, %.0f ms) -> %s\n",
              j["vertices"].get<size_t>(), j["triangles"].get<size_t>(), j["kind"].get<std::string>().c_str(),
              j["method"].get<std::string>().c_str(),
              j["watertight"].get<bool>() ? "watertight" : "NOT watertight", j["build_ms"].get<double>(),
              j["output"].get<std::string>().c_str());
  std::printf("  holds the cloud within %.2f mm (points outside: %lld, p99 %.2f mm; %.2g mm cells)%s%s\n",
              j["deviation_mm"].get<double>(), outside["points"].get<long long>(),
              outside["p99"].get<double>(), j["cell_mm"].get<double>(),
              j["published"].get<std::string>().empty() ? "" : ", published on ",
              j["published"].get<std::string>().c_str());
  std::printf(
      "  deviation: mesh to cloud p50 %.2f, p95 %.2f, max %.2f mm; "
      "cloud to mesh p50 %.2f, p95 %.2f, max %.2f mm\n",
      out["p50"].get<double>(), out["p95"].get<double>(), out["max"].get<double>(), in["p50"].get<double>(),
      in["p95"].get<double>(), in["max"].get<double>());
  if (!j["fallback"].get<std::string>().empty()) {
    std::printf("  fallback: %s\n", j["fallback"].get<std::string>().c_str());
  }
}

}  // namespace graspfill::cli
