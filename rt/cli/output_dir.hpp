// SPDX-License-Identifier: BSD-3-Clause
// The output folder of a CLI command and the files it writes there,
// checked before the command starts its work.
#pragma once

#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "error_text.hpp"
#include "graspfill/io/output_path.hpp"

namespace graspfill::cli {

/// Readies the files `names` (relative to `dir`, e.g. "claw/palm.ply") for
/// writing, before any work: without `force` none of them may exist or be
/// a symbolic link (all that do are listed); then `dir` and the folders
/// the names need are created and each file is checked
/// (io::CheckOutputFile: a regular file or missing, its folder writable). False, after
/// printing why as "graspfill <command>: ...", when a file cannot be
/// written.
inline bool PrepareOutputs(const std::filesystem::path& dir, const std::vector<std::string>& names,
                           bool force, const char* command) {
  namespace fs = std::filesystem;
  if (!force) {
    std::vector<std::string> existing;
    for (const std::string& name : names) {
      std::error_code ec;
      const fs::file_status status = fs::symlink_status(dir / name, ec);
      // A folder, device or FIFO is refused below, --force or not.
      if (fs::is_regular_file(status) || fs::is_symlink(status)) {
        existing.push_back((dir / name).string());
      }
    }
    if (!existing.empty()) {
      std::fprintf(stderr, "graspfill %s: refusing to overwrite existing output (use --force):\n", command);
      for (const std::string& path : existing) std::fprintf(stderr, "  %s\n", path.c_str());
      return false;
    }
  }
  try {
    io::PrepareOutputDir(dir.string());
    for (const std::string& name : names) {
      const fs::path parent = (dir / name).parent_path();
      if (parent != dir) io::PrepareOutputDir(parent.string());
      io::CheckOutputFile((dir / name).string(), force);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspfill %s: %s\n", command, ErrorText(e).c_str());
    return false;
  }
  return true;
}

}  // namespace graspfill::cli
