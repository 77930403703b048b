// SPDX-License-Identifier: BSD-3-Clause
#include "data_paths.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <system_error>

namespace graspfill::cli {

namespace fs = std::filesystem;

fs::path ExecutableDir() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (error) {
    throw std::runtime_error("cannot locate the graspfill executable (/proc/self/exe): " + error.message());
  }
  return exe.parent_path();
}

fs::path DataDir() {
  if (const char* dir = std::getenv("GRASPFILL_DATA_DIR"); dir != nullptr && *dir != '\0') {
    return fs::path(dir);
  }
  return (ExecutableDir().parent_path() / "share" / "graspfill").lexically_normal();
}

fs::path BundledRecordingDir() {
  const fs::path dir = DataDir() / "replay" / "default";
  if (!fs::is_regular_file(dir / "recording.lcmlog")) {
    throw std::runtime_error("no bundled recording at '" + (dir / "recording.lcmlog").string() +
                             "' (the data folder is $GRASPFILL_DATA_DIR, else the executable's "
                             "../share/graspfill)");
  }
  return dir;
}

fs::path InstalledClawsDir() { return DataDir() / "claws"; }

fs::path DefaultDemoDir() {
  const fs::path build = ExecutableDir().parent_path();
  if (fs::is_regular_file(build / "CMakeCache.txt")) return build / "demo";
  return fs::current_path() / "graspfill-demo";
}

}  // namespace graspfill::cli
