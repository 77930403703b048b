// SPDX-License-Identifier: BSD-3-Clause
// The --claw option shared by the commands (a built-in claw name or a claw
// description file), and the claw of a session description: how `synth`
// describes the claw it rendered, how `replay` and `live` build the claw a
// recording or a bus says it was made with, and whether two claws are the
// same.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/claw/claw_model.hpp"
#include "graspfill/claw/urdf_claw.hpp"
#include "graspfill/io/messages.hpp"
#include "number_parsing.hpp"

namespace graspfill::cli {

/// The description files in `claws_dir` by name (their *.json stems,
/// sorted); none where the folder is missing.
inline std::vector<std::string> ClawNamesIn(const std::filesystem::path& claws_dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(claws_dir, ec)) {
    if (entry.path().extension() == ".json" && entry.is_regular_file(ec)) {
      names.push_back(entry.path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// The file `spec` names: itself where something is there; else, for a name
/// without a folder, the description of that name in `claws_dir` (NAME or
/// NAME.json: `robotiq_3f` finds the installed robotiq_3f.json); else none.
inline std::optional<std::filesystem::path> FindClawFile(const std::string& spec,
                                                         const std::filesystem::path& claws_dir) {
  std::error_code ec;
  // Anything there is the loader's to judge (a FIFO, a folder: refused in words).
  if (std::filesystem::exists(spec, ec)) return std::filesystem::path(spec);
  const std::filesystem::path name(spec);
  if (spec.empty() || claws_dir.empty() || name.has_parent_path()) return std::nullopt;
  for (const std::filesystem::path& candidate : {claws_dir / name, claws_dir / (spec + ".json")}) {
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  }
  return std::nullopt;
}

/// True for the built-in claw names (the others are files).
inline bool IsBuiltinClaw(const std::string& spec) { return spec == "three-finger" || spec == "parallel"; }

/// `spec` as MakeClaw takes it: a built-in's name as it is, else the file
/// FindClawFile finds for it.
/// @throws UsageError for anything else, listing the built-ins and the
///   descriptions in `claws_dir`.
inline std::string ResolveClawSpec(const std::string& spec, const std::filesystem::path& claws_dir) {
  if (IsBuiltinClaw(spec)) return spec;
  if (const auto file = FindClawFile(spec, claws_dir)) return file->string();
  std::string known = "the built-ins are three-finger and parallel";
  const std::vector<std::string> installed = ClawNamesIn(claws_dir);
  if (!installed.empty()) {
    known += "; the descriptions in " + claws_dir.string() + ":";
    for (const std::string& n : installed) known += " " + n;
  }
  throw UsageError("unknown claw '" + spec + "': " + known +
                   "; or give a description (.json) or a URDF (.urdf) by its path");
}

/// "three-finger", "parallel", or a path to a description (.json) whose
/// meshes are found under `mesh_root` (default: beside the file), a URDF
/// (.urdf) or a URDF claw config (.json naming a URDF; urdf_claw.hpp).
/// A name of an installed description goes through ResolveClawSpec first.
/// Throws std::runtime_error with the spec on failure.
inline claw::ClawModel MakeClaw(const std::string& spec, const std::string& mesh_root = "") {
  if (spec == "three-finger") return claw::ClawModel::ThreeFinger();
  if (spec == "parallel") return claw::ClawModel::Parallel();
  return claw::ClawModel::Load(spec, mesh_root);
}

namespace internal {

// The procedural dimensions by name, in the order scene.json writes them.
struct ProceduralField {
  const char* name;
  double claw::ProceduralClawConfig::*member;
};
inline const std::vector<ProceduralField>& ProceduralFields() {
  using C = claw::ProceduralClawConfig;
  static const std::vector<ProceduralField> fields = {{"palm_radius_m", &C::palm_radius_m},
                                                      {"palm_thickness_m", &C::palm_thickness_m},
                                                      {"finger_length_m", &C::finger_length_m},
                                                      {"finger_width_m", &C::finger_width_m},
                                                      {"finger_thickness_m", &C::finger_thickness_m},
                                                      {"min_opening_m", &C::min_opening_m},
                                                      {"max_opening_m", &C::max_opening_m}};
  return fields;
}

// Surface area and bounds of one mesh mapped by T.
struct MeshShape {
  Eigen::AlignedBox3d box;
  double area{0.0};
};
inline MeshShape ShapeOf(const TriangleMesh& mesh, const Eigen::Isometry3d& T) {
  MeshShape s;
  std::vector<Eigen::Vector3d> v;
  v.reserve(mesh.vertices.size());
  for (const Eigen::Vector3f& p : mesh.vertices) {
    v.push_back(T * p.cast<double>());
    s.box.extend(v.back());
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    s.area += 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm();
  }
  return s;
}

}  // namespace internal

/// The JSON text of a procedural claw's dimensions, as session descriptions
/// carry it (the keys of scene.json's "claw.used").
inline std::string ProceduralClawText(const claw::ProceduralClawConfig& config) {
  nlohmann::ordered_json j;
  for (const internal::ProceduralField& f : internal::ProceduralFields()) {
    j[f.name] = config.*(f.member);
  }
  return j.dump();
}

/// Parses ProceduralClawText's format: every field present, a finite
/// number, nothing else. Throws std::runtime_error naming the field.
inline claw::ProceduralClawConfig ParseProceduralClawText(const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("claw dimensions: bad JSON: ") + e.what());
  }
  if (!j.is_object()) throw std::runtime_error("claw dimensions: not a JSON object");
  claw::ProceduralClawConfig config;
  for (const internal::ProceduralField& f : internal::ProceduralFields()) {
    if (!j.contains(f.name) || !j[f.name].is_number() || !std::isfinite(j[f.name].get<double>())) {
      throw std::runtime_error(std::string("claw dimensions: ") + f.name +
                               ": missing or not a finite number");
    }
    config.*(f.member) = j[f.name].get<double>();
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const internal::ProceduralField& f : internal::ProceduralFields()) known |= it.key() == f.name;
    if (!known) throw std::runtime_error("claw dimensions: unknown key '" + it.key() + "'");
  }
  return config;
}

/// Sets the claw of *session to the built-in `name` with these dimensions.
inline void DescribeBuiltinClaw(const std::string& name, const claw::ProceduralClawConfig& config,
                                io::SessionDescription* session) {
  session->claw_kind = io::SessionClawKind::kBuiltin;
  session->claw_name = name;
  session->claw_text = ProceduralClawText(config);
  session->claw_source.clear();
  session->claw_mesh_root.clear();
}

/// Sets the claw of *session to the file claw `spec` (MakeClaw's): a
/// description as its file's text, a URDF claw as UrdfClawBundle's text
/// (the config with the URDF inside), with the path given and the mesh
/// root used (absolute: `mesh_root`, else the description's folder; a URDF
/// claw without one keeps its URDF's folder in its text), so that a replay
/// elsewhere on this machine finds the meshes.
inline void DescribeFileClaw(const std::string& spec, const std::string& mesh_root,
                             const claw::ClawModel& model, io::SessionDescription* session) {
  namespace fs = std::filesystem;
  session->claw_name = model.name();
  session->claw_source = spec;
  const auto absolute = [](const fs::path& p) { return fs::absolute(p).lexically_normal().string(); };
  if (claw::IsUrdfClaw(spec)) {
    session->claw_kind = io::SessionClawKind::kUrdf;
    session->claw_text = claw::UrdfClawBundle(spec, mesh_root);
    session->claw_mesh_root = mesh_root.empty() ? "" : absolute(mesh_root);
  } else {
    session->claw_mesh_root =
        absolute(mesh_root.empty() ? fs::path(spec).parent_path() : fs::path(mesh_root));
    session->claw_kind = io::SessionClawKind::kDescription;
    std::ifstream in(spec, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) throw std::runtime_error(spec + ": cannot read the claw description");
    session->claw_text = text.str();
  }
}

/// How a message names a session's claw: "parallel", "parallel (as recorded:
/// finger_length_m 0.12)" when its dimensions are not the built-in's,
/// "description 'franka_hand' (config/claws/franka_hand.json)", "URDF 'x'".
inline std::string SessionClawLabel(const io::SessionDescription& session) {
  switch (session.claw_kind) {
    case io::SessionClawKind::kBuiltin: {
      std::string changed;
      try {
        const claw::ProceduralClawConfig used = ParseProceduralClawText(session.claw_text);
        const claw::ProceduralClawConfig defaults;
        for (const internal::ProceduralField& f : internal::ProceduralFields()) {
          if (used.*(f.member) == defaults.*(f.member)) continue;
          std::ostringstream value;
          value << used.*(f.member);
          changed += (changed.empty() ? "" : ", ") + std::string(f.name) + " " + value.str();
        }
      } catch (const std::exception&) {
        changed = "unreadable dimensions";
      }
      return changed.empty() ? session.claw_name : session.claw_name + " (as recorded: " + changed + ")";
    }
    case io::SessionClawKind::kDescription:
      return "description '" + session.claw_name + "'" +
             (session.claw_source.empty() ? "" : " (" + session.claw_source + ")");
    case io::SessionClawKind::kUrdf:
      return "URDF '" + session.claw_name + "'" +
             (session.claw_source.empty() ? "" : " (" + session.claw_source + ")");
  }
  return session.claw_name;
}

/// Builds the claw a session description gives, from its text in memory:
/// nothing a description (from the bus or a log) says is a path graspfill
/// writes or reads. A description's or URDF's meshes are read only under
/// the local `mesh_root` (--claw-mesh-root, the rig config's
/// claw.mesh_root): relative, no '..' (claw/mesh_path.hpp); the session's
/// own claw_mesh_root, claw_source and a URDF bundle's urdf_dir are not
/// used, only named in the error as a hint. Throws std::runtime_error
/// naming the claw.
inline claw::ClawModel MakeSessionClaw(const io::SessionDescription& session,
                                       const std::string& mesh_root = "") {
  const std::string label = SessionClawLabel(session);
  try {
    switch (session.claw_kind) {
      case io::SessionClawKind::kBuiltin: {
        const claw::ProceduralClawConfig config = ParseProceduralClawText(session.claw_text);
        if (session.claw_name == "three-finger") return claw::ClawModel::ThreeFinger(config);
        if (session.claw_name == "parallel") return claw::ClawModel::Parallel(config);
        throw std::runtime_error("unknown built-in claw");
      }
      case io::SessionClawKind::kDescription:
        return claw::ClawModel::LoadDescriptionText(
            session.claw_text, session.claw_name, "claw description '" + session.claw_name + "'", mesh_root);
      case io::SessionClawKind::kUrdf:
        return claw::LoadUrdfClawText(session.claw_text, "URDF claw '" + session.claw_name + "'", mesh_root);
    }
    throw std::runtime_error("unknown claw kind");
  } catch (const std::exception& e) {
    const std::string recorded =
        session.claw_mesh_root.empty() ? "" : "; it was made with meshes in " + session.claw_mesh_root;
    throw std::runtime_error("the session description's claw " + label + ": " + e.what() +
                             " (pass --claw SPEC, or --claw-mesh-root DIR for its meshes" + recorded + ")");
  }
}

/// True when the two claws have the same links, posed alike with the same
/// surfaces (bounds within 10 um, areas within 0.01%) at openings across
/// the usual range: the same claw, whichever way it was given (a built-in
/// and the description `synth` wrote of it compare equal).
inline bool SameClaw(const claw::ClawModel& a, const claw::ClawModel& b) {
  if (a.links().size() != b.links().size()) return false;
  constexpr double kBoundsTolerance = 1e-5;  // m: PLY floats, rpy round trips
  constexpr double kAreaTolerance = 1e-4;    // relative
  for (double opening : {0.0, 0.01, 0.03, 0.06, 0.5, 1.0}) {
    const std::vector<Eigen::Isometry3d> pa = a.LinkPoses(opening);
    const std::vector<Eigen::Isometry3d> pb = b.LinkPoses(opening);
    for (size_t i = 0; i < pa.size(); ++i) {
      const claw::Link& la = a.links()[i];
      const claw::Link& lb = b.links()[i];
      if (la.mesh.empty() != lb.mesh.empty()) return false;
      if (la.mesh.empty()) continue;
      const internal::MeshShape sa = internal::ShapeOf(la.mesh, pa[i] * la.T_link_mesh);
      const internal::MeshShape sb = internal::ShapeOf(lb.mesh, pb[i] * lb.T_link_mesh);
      if ((sa.box.min() - sb.box.min()).cwiseAbs().maxCoeff() > kBoundsTolerance ||
          (sa.box.max() - sb.box.max()).cwiseAbs().maxCoeff() > kBoundsTolerance ||
          std::abs(sa.area - sb.area) > kAreaTolerance * std::max(sa.area, sb.area)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace graspfill::cli
