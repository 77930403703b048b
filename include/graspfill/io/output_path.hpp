// SPDX-License-Identifier: BSD-3-Clause
// Checks of a command's output paths, made before the command starts its
// work, so that an output that cannot be written is found at once rather
// than after a whole replay.
#pragma once

#include <string>

namespace graspfill::io {

/// Checks that the file `path` can be written as an output.
///
/// Refused: a directory, a character or block device, a FIFO or a socket
/// (or a link to one), even with `overwrite`: only regular files are
/// written; an existing file or any symbolic link (even a dangling one)
/// unless `overwrite`; a folder that does not exist, is not a
/// folder or cannot be written to (tried by creating and removing a
/// temporary file in it, which tells the truth for root and read-only
/// mounts alike).
/// @param overwrite the command's --force.
/// @throws std::runtime_error "'<path>' <why>" (with strerror where the
///   system said why); a message about an existing file or link ends with
///   "pass --force to overwrite it".
void CheckOutputFile(const std::string& path, bool overwrite);

/// Creates the output folder `dir` and its parents if missing, then checks
/// that it is a writable folder (as CheckOutputFile checks a file's folder).
/// @throws std::runtime_error "cannot create '<dir>': <strerror>" or
///   "'<dir>' ...: <strerror>".
void PrepareOutputDir(const std::string& dir);

}  // namespace graspfill::io
