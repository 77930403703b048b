// SPDX-License-Identifier: BSD-3-Clause
// Pieces of atomic_file.cpp that output_path.cpp shares (not API).
#pragma once

#include <string>

namespace graspfill::io::internal {

/// `path` with its last component's symbolic links followed (relative
/// targets against the link's folder), as open() would; `path` itself if it
/// is not a link.
std::string FollowSymlinks(const std::string& path);

/// Creates a new, empty temporary file `DIR/.NAME.tmp-XXXXXX` beside `path`
/// (mode 0666 less the umask, never through a link); its descriptor, or -1
/// with errno set.
int CreateTempFile(const std::string& path, std::string* temp_path);

/// What is at `path` (not following a link) where it is a device, a FIFO
/// or a socket: "a character device", "a block device", "a FIFO (named
/// pipe)" or "a socket"; nullptr for anything else (missing, a regular
/// file, a folder, a symbolic link).
const char* SpecialFileKind(const std::string& path);

/// The message's end for such a file: graspfill writes regular files only.
inline std::string NotWrittenBecause(const char* kind) {
  return "is " + std::string(kind) +
         ", not a regular file (only regular files are written, "
         "even with --force)";
}

}  // namespace graspfill::io::internal
