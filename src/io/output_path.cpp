// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/output_path.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "atomic_file_internal.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Refuse(const std::string& path, const std::string& why) {
  throw std::runtime_error("'" + path + "' " + why);
}

// A folder we can create files in: tried, not guessed from permission bits
// (root passes those, a read-only mount fails them all).
void CheckWritableDir(const fs::path& dir, const std::string& shown) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (!fs::exists(status)) {
    Refuse(shown, "cannot be written: folder '" + dir.string() + "' does not exist");
  }
  if (!fs::is_directory(status)) {
    Refuse(shown, "cannot be written: '" + dir.string() + "' is not a folder");
  }
  std::string probe;
  const int fd = internal::CreateTempFile((dir / "probe").string(), &probe);
  if (fd < 0) {
    const int error = errno;
    Refuse(shown, "cannot be written: folder '" + dir.string() + "': " + std::strerror(error));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace

void CheckOutputFile(const std::string& path, bool overwrite) {
  if (path.empty()) throw std::runtime_error("empty output path");
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (fs::is_symlink(link)) {
    if (!overwrite) {
      Refuse(path, "is a symbolic link (to '" + fs::read_symlink(path, ec).string() +
                       "'); pass --force to overwrite it");
    }
  } else if (fs::is_directory(link)) {
    Refuse(path, "is a folder");
  } else if (const char* kind = internal::SpecialFileKind(path)) {
    Refuse(path, internal::NotWrittenBecause(kind));
  } else if (fs::exists(link) && !overwrite) {
    Refuse(path, "exists; pass --force to overwrite it");
  }
  // Where the bytes will go: a link's target (--force), in its own folder.
  const fs::path target(internal::FollowSymlinks(path));
  if (fs::is_directory(target, ec)) Refuse(path, "points to a folder");
  if (const char* kind = internal::SpecialFileKind(target.string())) {
    Refuse(path, "points to '" + target.string() + "', which " + internal::NotWrittenBecause(kind));
  }
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  CheckWritableDir(dir, path);
}

void PrepareOutputDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create '" + dir + "': " + ec.message());
  CheckWritableDir(dir, dir);
}

}  // namespace graspfill::io
