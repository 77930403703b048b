// SPDX-License-Identifier: BSD-3-Clause
// Where the CLI finds its data: relative to the executable, never by a path
// compiled in. Installed, the executable is <prefix>/bin/graspfill and the
// data <prefix>/share/graspfill/ (replay/, the bundled recordings; claws/,
// the claw descriptions); the build tree has the same layout (build/bin/ and
// build/share/graspfill/, whose entries link to the source tree's replay/
// and config/claws/, cmake/GraspfillPackage.cmake).
#pragma once

#include <filesystem>

namespace graspfill::cli {

/// The folder of the running executable (/proc/self/exe, links resolved).
/// @throws std::runtime_error if it cannot be read.
std::filesystem::path ExecutableDir();

/// graspfill's data folder: $GRASPFILL_DATA_DIR when set and not empty,
/// else <executable folder>/../share/graspfill. Not checked for existence.
std::filesystem::path DataDir();

/// The bundled recording's folder, DataDir()/replay/default.
/// @throws std::runtime_error naming the folder and how it is found when it
///   holds no recording.lcmlog.
std::filesystem::path BundledRecordingDir();

/// The installed claw descriptions' folder, DataDir()/claws (not checked).
std::filesystem::path InstalledClawsDir();

/// Where `graspfill demo` writes unless told: <build>/demo when run from a
/// build tree (the executable's parent folder holds CMakeCache.txt), else
/// graspfill-demo in the current directory.
std::filesystem::path DefaultDemoDir();

}  // namespace graspfill::cli
