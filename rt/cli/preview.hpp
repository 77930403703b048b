// SPDX-License-Identifier: BSD-3-Clause
// --preview DIR of replay and repair: a picture of the cloud before and
// after the repair (view/contact_sheet.hpp) as DIR/<output's stem>.png,
// readied with the other outputs before the work, written after it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "graspfill/io/png.hpp"
#include "graspfill/view/contact_sheet.hpp"
#include "output_dir.hpp"

namespace graspfill::cli {

/// The preview of the output `output_path` in `dir`.
inline std::string PreviewPath(const std::string& dir, const std::string& output_path) {
  return (std::filesystem::path(dir) / (std::filesystem::path(output_path).stem().string() + ".png"))
      .string();
}

/// Creates `dir` and checks that the preview can be written there (not
/// over an existing file without `force`); false after printing why.
inline bool PreparePreview(const std::string& dir, const std::string& output_path, bool force,
                           const char* command) {
  const std::string name = std::filesystem::path(PreviewPath(dir, output_path)).filename().string();
  return PrepareOutputs(dir, {name}, force, command);
}

/// Writes the preview: `before` beside `after`, or `after` alone when
/// `before` is null (no repair ran). Returns the path written.
/// @param force replace an existing file (else one there is an error).
/// @throws std::runtime_error naming the file if it cannot be written.
inline std::string WritePreview(const std::string& dir, const std::string& output_path,
                                const ObjectCloud* before, const ObjectCloud& after, bool force) {
  const std::string name = std::filesystem::path(output_path).filename().string();
  std::vector<view::SheetCloud> clouds;
  if (before != nullptr) clouds.push_back({before, "before repair"});
  clouds.push_back({&after, before != nullptr ? "after: " + name : name});
  const std::string path = PreviewPath(dir, output_path);
  io::WritePng(path, view::RenderSheet(clouds, view::SheetConfig{}), io::ReplaceIf(force));
  return path;
}

}  // namespace graspfill::cli
