// SPDX-License-Identifier: BSD-3-Clause
// Pictures for people as PNG files (`graspfill view`, `--preview`).
//
// File I/O at the API boundary: failures throw std::runtime_error naming
// the path. Reentrant; any thread.
#pragma once

#include <string>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/types.hpp"

namespace graspfill::io {

/// Writes `image` as an 8-bit RGB PNG, atomically (io/atomic_file.hpp: a
/// failed write leaves an existing file as it was). Encoded by Open3D's
/// image I/O (libpng); the same image always gives the same bytes.
/// @throws std::runtime_error "cannot write PNG '<path>': <why>" on an
///   empty image, a pixel buffer that is not width * height * 3 bytes, or a
///   failed write (with the system's reason where it gave one).
/// @param if_exists kFail: refuse to replace anything at `path` (see
///   io/atomic_file.hpp; a command without --force).
void WritePng(const std::string& path, const RgbImage& image, IfExists if_exists = IfExists::kReplace);

}  // namespace graspfill::io
