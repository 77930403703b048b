// SPDX-License-Identifier: BSD-3-Clause
// Where a claw's mesh reference is read from when the claw's text came from
// outside this machine (a session description on the bus or in a log): a
// publisher must not make graspfill read whatever file it names, so such a
// reference resolves only inside the mesh root the local user gave.
#pragma once

#include <filesystem>
#include <string>

namespace graspfill::claw {

/// `reference` (a mesh path from claw text of a session description) under
/// `root` (the local --claw-mesh-root). Throws std::runtime_error saying
/// why when it could lead anywhere else: `root` empty (no local mesh root
/// given), `reference` empty, absolute, or with a ".." part.
std::filesystem::path ConfinedMeshPath(const std::string& root, const std::string& reference);

}  // namespace graspfill::claw
