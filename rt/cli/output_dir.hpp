// The output folder of a CLI command, created on demand.
#pragma once

#include <cstdio>
#include <filesystem>
#include <system_error>

namespace graspfill::cli {

/// Creates `dir` (and its parents) if missing; false, after printing why
/// as "graspfill <command>: cannot create ...", when that fails.
inline bool CreateOutputDir(const std::filesystem::path& dir, const char* command) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!ec) return true;
  std::fprintf(stderr, "graspfill %s: cannot create '%s': %s\n", command, dir.string().c_str(),
               ec.message().c_str());
  return false;
}

}  // namespace graspfill::cli
