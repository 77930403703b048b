// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/cloud_file.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include "graspfill/io/pcd.hpp"
#include "graspfill/io/ply.hpp"

namespace graspfill::io {

namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

CloudFileFormat CloudFileFormatOf(const std::string& path) {
  const std::string ext = LowerExtension(path);
  if (ext == ".ply") return CloudFileFormat::kPly;
  if (ext == ".pcd") return CloudFileFormat::kPcd;
  throw std::invalid_argument("'" + path + "': a cloud is written as .ply or .pcd, " +
                              (ext.empty() ? std::string("and this name has no extension") : "not " + ext));
}

void WriteCloudFile(const std::string& path, const ObjectCloud& cloud, IfExists if_exists) {
  switch (CloudFileFormatOf(path)) {
    case CloudFileFormat::kPly:
      return WriteCloudPly(path, cloud, if_exists);
    case CloudFileFormat::kPcd:
      return WriteCloudPcd(path, cloud, if_exists);
  }
}

ObjectCloud ReadCloudFile(const std::string& path) {
  if (LowerExtension(path) == ".pcd") {
    throw std::invalid_argument("'" + path +
                                "': PCD is written, not read; give the cloud as .ply "
                                "(PCL's pcl_pcd2ply converts it)");
  }
  return ReadCloudPly(path);
}

}  // namespace graspfill::io
