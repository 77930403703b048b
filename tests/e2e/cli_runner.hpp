// SPDX-License-Identifier: BSD-3-Clause
// Runs the graspfill CLI as a child process for the end-to-end tests.
#pragma once

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace graspfill::testing {

struct CliResult {
  int exit_code{-1};
  std::string output;  ///< stdout and stderr together
};

/// Runs the shell command `command`, keeping what it printed on stdout.
inline CliResult RunShell(const std::string& command) {
  CliResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// Runs `graspfill <args>` with LCM on the in-process memq:// provider so
/// that no test traffic leaves the process. `shell_prefix`, if given, runs
/// first in the same shell (e.g. "trap '' XFSZ; ulimit -f 16; " for a
/// full disk).
inline CliResult RunCli(const std::string& args, const std::string& shell_prefix = "") {
  return RunShell(shell_prefix + "LCM_DEFAULT_URL=memq:// " GRASPFILL_CLI " " + args + " 2>&1");
}

/// A fresh, empty scratch folder under the build tree.
inline std::string ScratchDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(GRASPFILL_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace graspfill::testing
