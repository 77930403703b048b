// SPDX-License-Identifier: BSD-3-Clause
// An object cloud's file, by its name: `.ply` (io/ply.hpp) or `.pcd`
// (io/pcd.hpp), so that a file's bytes always match its extension.
#pragma once

#include <string>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

enum class CloudFileFormat { kPly, kPcd };

/// The format an output's extension names (case-insensitive).
/// @throws std::invalid_argument "'<path>': ..." naming the accepted
///   extensions, for any other extension or none.
CloudFileFormat CloudFileFormatOf(const std::string& path);

/// Writes `cloud` in the format of `path`'s extension (WriteCloudPly or
/// WriteCloudPcd).
/// @throws std::invalid_argument as CloudFileFormatOf, before anything is
///   written; std::runtime_error as the writers.
void WriteCloudFile(const std::string& path, const ObjectCloud& cloud,
                    IfExists if_exists = IfExists::kReplace);

/// Reads a cloud: PLY (ReadCloudPly), whatever the name unless it is
/// `.pcd`. PCD is written for PCL-based tools, not read.
/// @throws std::invalid_argument for a .pcd, saying to convert it;
///   std::runtime_error as ReadCloudPly.
ObjectCloud ReadCloudFile(const std::string& path);

}  // namespace graspfill::io
