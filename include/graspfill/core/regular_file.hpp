// SPDX-License-Identifier: BSD-3-Clause
// Reading files by name only when they are regular files. A FIFO blocks
// open() and read() until a writer comes (forever, for a mistyped path), a
// device such as /dev/zero or /dev/urandom never ends: every file graspfill
// reads by name (logs, rig configs, claw descriptions, URDFs, meshes) is
// checked here first, with one wording for every refusal.
#pragma once

#include <cstdint>
#include <string>

namespace graspfill {

/// Why `path` cannot be read as a file, or "" when it names a regular file
/// (symbolic links followed): "no such file", "is a directory", "not a
/// regular file (a FIFO, socket or device: it could block or never end)",
/// or the system's reason (e.g. "Permission denied").
std::string NotARegularFile(const std::string& path);

/// The whole of the regular file `path`. It is opened without blocking and
/// checked again on the open descriptor, so a FIFO put in its place after
/// the check cannot block either; more than `max_bytes` is refused before
/// anything is read.
/// @throws std::runtime_error "<what> '<path>': <reason>", the reason as
///   NotARegularFile's, "larger than <max_bytes> bytes (<size> bytes)" or
///   the system's.
std::string ReadRegularFile(const std::string& path, int64_t max_bytes, const std::string& what);

}  // namespace graspfill
