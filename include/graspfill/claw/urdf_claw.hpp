// SPDX-License-Identifier: BSD-3-Clause
// Claws from a robot's URDF (urdfdom), optionally with a small JSON config
// beside it that says how graspfill's single `opening` drives the joints.
// Produces the same ClawModel as a description file (claw_model.hpp): links
// with their meshes in link frames, joints with limits, mimic joints
// following their master. Format and rules: config/claws/README.md.
#pragma once

#include <string>

#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw {

/// True when `path` names a URDF claw: a `.urdf` file, or a JSON file with a
/// "urdf" or "urdf_text" key (a URDF claw config). Reads the file's head;
/// false when it cannot be read (the loader then names the problem).
bool IsUrdfClaw(const std::string& path);

/// Loads a URDF claw from a `.urdf` file (default mapping) or a config
/// naming one. Relative mesh paths and `package://PKG/...` URIs resolve
/// against `mesh_root` when given, else against the URDF's folder; a
/// config's relative "urdf" path against `mesh_root` when given, else the
/// config's folder. Throws std::runtime_error naming the file, and the
/// link or joint, on bad input.
ClawModel LoadUrdfClaw(const std::string& path, const std::string& mesh_root = "");

/// The claw at `path` as one self-contained JSON text: the config's keys
/// (none for a bare URDF), "urdf_text" with the URDF itself and "urdf_dir"
/// (its absolute folder, where relative meshes are looked up without a mesh
/// root). What a session description carries for a URDF claw. `mesh_root`
/// as for LoadUrdfClaw (where a config's relative "urdf" is).
std::string UrdfClawBundle(const std::string& path, const std::string& mesh_root = "");

/// Loads a URDF claw from a config text (UrdfClawBundle's, or any config
/// with "urdf_text") or from the URDF's XML itself (default mapping);
/// `label` names it in errors. The text comes from elsewhere (a session
/// description), so its meshes are read only under the local `mesh_root`
/// (mesh_path.hpp: relative or package://, no '..', none without a root);
/// its "urdf_dir" is not used.
ClawModel LoadUrdfClawText(const std::string& config_text, const std::string& label,
                           const std::string& mesh_root = "");

}  // namespace graspfill::claw
