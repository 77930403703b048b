// SPDX-License-Identifier: BSD-3-Clause
// --mesh-out FILE.{ply,stl,obj} (replay, repair): the collision mesh of the
// command's model (mesh/collision_mesh.hpp), written after the cloud, with
// its deviation from the cloud printed and in --json.
#pragma once

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "number_parsing.hpp"
#include "graspfill/io/mesh_export.hpp"
#include "graspfill/mesh/collision_mesh.hpp"
#include "graspfill/mesh/mesh_deviation.hpp"
#include "graspfill/synth/mesh_sampling.hpp"

namespace graspfill::cli {

/// Checks --mesh-out's path once the command line is parsed: a known
/// extension, not the cloud's own output.
/// @throws UsageError saying which.
inline void CheckMeshOutOption(const std::string& mesh_path, const std::string& cloud_path) {
  if (!io::MeshFormatOf(mesh_path)) {
    throw UsageError("--mesh-out '" + mesh_path + "': unknown extension (use .ply, .stl or .obj)");
  }
  std::error_code ec;
  if (mesh_path == cloud_path || std::filesystem::equivalent(mesh_path, cloud_path, ec)) {
    throw UsageError("--mesh-out '" + mesh_path + "' is the cloud's output (-o) too");
  }
}

/// Builds the collision mesh of `cloud`, writes it to `path` (replacing a
/// file there only with `force`) and measures it against the cloud.
/// @return the report (--json's "mesh"; PrintCollisionMesh prints it).
/// @throws std::exception from the mesh (a cloud too small) or the write.
inline nlohmann::ordered_json WriteCollisionMesh(const std::string& path, const ObjectCloud& cloud,
                                                 bool force) {
  const auto t0 = std::chrono::steady_clock::now();
  const mesh::CollisionMeshConfig config;
  const TriangleMesh m = mesh::BuildCollisionMesh(cloud, config);
  const auto t1 = std::chrono::steady_clock::now();
  io::WriteMesh(path, m, io::ReplaceIf(force));
  const mesh::MeshDeviation d = mesh::MeasureDeviation(m, cloud);
  auto mm = [](double meters) { return meters * 1e3; };
  nlohmann::ordered_json j;
  j["output"] = path;
  j["vertices"] = m.vertices.size();
  j["triangles"] = m.triangles.size();
  j["closed"] = synth::IsClosedOriented(m);
  j["cell_mm"] = mm(config.cell_m);
  j["surface_to_cloud_mm"] = {{"p50", mm(d.surface_to_cloud_p50_m)},
                              {"p95", mm(d.surface_to_cloud_p95_m)},
                              {"max", mm(d.surface_to_cloud_max_m)}};
  j["cloud_to_surface_mm"] = {{"p50", mm(d.cloud_to_surface_p50_m)},
                              {"p95", mm(d.cloud_to_surface_p95_m)},
                              {"max", mm(d.cloud_to_surface_max_m)}};
  j["build_ms"] = std::chrono::duration<double, std::milli>(t1 - t0).count();
  return j;
}

/// Prints WriteCollisionMesh's report in two lines.
inline void PrintCollisionMesh(const nlohmann::ordered_json& j) {
  const auto& out = j["surface_to_cloud_mm"];
  const auto& in = j["cloud_to_surface_mm"];
  std::printf("collision mesh: %zu vertices, %zu triangles (%s, %g mm cells, %.0f ms) -> %s\n",
              j["vertices"].get<size_t>(), j["triangles"].get<size_t>(),
              j["closed"].get<bool>() ? "closed" : "NOT closed", j["cell_mm"].get<double>(),
              j["build_ms"].get<double>(), j["output"].get<std::string>().c_str());
  std::printf("  deviation: mesh to cloud p50 %.2f, p95 %.2f, max %.2f mm; "
              "cloud to mesh p50 %.2f, p95 %.2f, max %.2f mm\n",
              out["p50"].get<double>(), out["p95"].get<double>(), out["max"].get<double>(),
              in["p50"].get<double>(), in["p95"].get<double>(), in["max"].get<double>());
}

}  // namespace graspfill::cli
