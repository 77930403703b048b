// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/mesh_path.hpp"

#include <stdexcept>

namespace graspfill::claw {

namespace fs = std::filesystem;

fs::path ConfinedMeshPath(const std::string& root, const std::string& reference) {
  const std::string quoted = "mesh '" + reference + "'";
  if (root.empty()) {
    throw std::runtime_error(quoted +
                             ": the claw of a session description reads its meshes "
                             "only under the local mesh root, and none was given");
  }
  const fs::path p(reference);
  if (reference.empty()) throw std::runtime_error("mesh '': empty path");
  if (p.has_root_path()) {
    throw std::runtime_error(quoted +
                             ": an absolute path; a session description's claw may "
                             "name meshes only relative to the local mesh root");
  }
  for (const fs::path& part : p) {
    if (part == "..") {
      throw std::runtime_error(quoted +
                               ": a '..' part; a session description's claw may name "
                               "meshes only inside the local mesh root");
    }
  }
  return fs::path(root) / p;
}

}  // namespace graspfill::claw
