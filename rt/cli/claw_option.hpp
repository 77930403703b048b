// The --claw option shared by the commands: a built-in claw name or a claw
// description file.
#pragma once

#include <string>

#include "graspfill/claw/claw_model.hpp"

namespace graspfill::cli {

/// "three-finger", "parallel", or a path to a description (.json) whose
/// meshes are found under `mesh_root` (default: beside the file).
/// Throws std::runtime_error with the spec on failure.
inline claw::ClawModel MakeClaw(const std::string& spec, const std::string& mesh_root = "") {
  if (spec == "three-finger") return claw::ClawModel::ThreeFinger();
  if (spec == "parallel") return claw::ClawModel::Parallel();
  return claw::ClawModel::Load(spec, mesh_root);
}

}  // namespace graspfill::cli
