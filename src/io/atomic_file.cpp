// SPDX-License-Identifier: BSD-3-Clause
// Temporary file + fsync + rename (POSIX rename replaces the target
// atomically within one file system, which the temporary file's place in
// the target's folder guarantees). Without kReplace the temporary file is
// put in place by renameat2(RENAME_NOREPLACE), or link(2) + unlink where
// the file system has no such rename: both fail with EEXIST rather than
// replace what another writer put there meanwhile.
#include "graspfill/io/atomic_file.hpp"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_NOREPLACE (glibc >= 2.28)
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "atomic_file_internal.hpp"

namespace graspfill::io {
namespace {

namespace fs = std::filesystem;

// Symbolic links followed before giving up (Linux's own limit is 40).
constexpr int kMaxSymlinkHops = 40;
// Names tried before giving up when temporary names collide.
constexpr int kMaxNameAttempts = 100;

}  // namespace

namespace internal {

std::string FollowSymlinks(const std::string& path) {
  fs::path p(path);
  for (int hop = 0; hop < kMaxSymlinkHops; ++hop) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p.string();
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return p.string();
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  return p.string();
}

int CreateTempFile(const std::string& path, std::string* temp_path) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  fs::path dir = target.parent_path();
  const std::string name = target.filename().string();
  for (int attempt = 0; attempt < kMaxNameAttempts; ++attempt) {
    const auto ticks =
        static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
    char suffix[32];
    std::snprintf(suffix, sizeof(suffix), "%06llx",
                  (ticks ^ (static_cast<unsigned long long>(::getpid()) << 20) ^
                   (static_cast<unsigned long long>(counter++) << 8)) &
                      0xffffffULL);
    const fs::path temp = dir / ("." + name + ".tmp-" + suffix);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      *temp_path = temp.string();
      return fd;
    }
    if (errno != EEXIST) return -1;
  }
  errno = EEXIST;
  return -1;
}

const char* SpecialFileKind(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return nullptr;
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISFIFO(st.st_mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return nullptr;
}

}  // namespace internal

namespace {

// Puts `temp` at `path` only if nothing is there: 0, or -1 with errno set
// (EEXIST where something is).
int PlaceNew(const std::string& temp, const std::string& path) {
  if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP && errno != EOPNOTSUPP) return -1;
  // No RENAME_NOREPLACE here (NFS, some FUSE): a hard link fails the same way.
  if (::link(temp.c_str(), path.c_str()) != 0) return -1;
  ::unlink(temp.c_str());
  return 0;
}

// EEXIST's text, with what to do; `meanwhile`: the file appeared while
// this one was being written (another writer won the race).
std::string FileExistsText(bool meanwhile) {
  return std::string(std::strerror(EEXIST)) + (meanwhile ? " (created while this one was written)" : "") +
         "; pass --force to overwrite it";
}

}  // namespace

AtomicFile::AtomicFile(const std::string& path, const std::string& what, IfExists if_exists)
    : what_(what),
      if_exists_(if_exists),
      // kFail: a link at the path is something there, not a way to a file.
      path_(if_exists == IfExists::kReplace ? internal::FollowSymlinks(path) : path) {
  CheckTarget(/*at_commit=*/false);
  fd_ = internal::CreateTempFile(path_, &temp_path_);
  if (fd_ < 0) {
    const int error = errno;
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
  }
}

void AtomicFile::CheckTarget(bool at_commit) const {
  struct stat st {};
  if (::lstat(path_.c_str(), &st) != 0) return;  // nothing there (else the write says why)
  if (const char* kind = internal::SpecialFileKind(path_)) {
    throw std::runtime_error(what_ + " '" + path_ + "': " + internal::NotWrittenBecause(kind));
  }
  if (S_ISDIR(st.st_mode)) {
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(EISDIR));
  }
  if (if_exists_ == IfExists::kFail) {
    throw std::runtime_error(what_ + " '" + path_ + "': " + FileExistsText(at_commit));
  }
}

AtomicFile::~AtomicFile() { Abandon(); }

void AtomicFile::Fail(int error) {
  Abandon();
  throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
}

void AtomicFile::Commit() {
  if (fd_ < 0) throw std::runtime_error(what_ + " '" + path_ + "': already committed or abandoned");
  if (::fsync(fd_) != 0) Fail(errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
  }
  // Looked at again: a device or FIFO may have appeared since the start.
  try {
    CheckTarget(/*at_commit=*/true);
  } catch (const std::exception&) {
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    throw;
  }
  const int placed = if_exists_ == IfExists::kReplace ? std::rename(temp_path_.c_str(), path_.c_str())
                                                      : PlaceNew(temp_path_, path_);
  if (placed != 0) {
    const int error = errno;
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    throw std::runtime_error(what_ + " '" + path_ +
                             "': " + (error == EEXIST ? FileExistsText(true) : std::strerror(error)));
  }
  temp_path_.clear();
  // The rename itself reaches the disk with the folder's next flush; best
  // effort, the file is complete either way.
  std::string dir = fs::path(path_).parent_path().string();
  if (dir.empty()) dir = ".";
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

void AtomicFile::Abandon() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!temp_path_.empty()) {
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
  }
}

void WriteFileAtomically(const std::string& path, const std::string& bytes, const std::string& what,
                         IfExists if_exists) {
  AtomicFile file(path, what, if_exists);
  const char* data = bytes.data();
  size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(file.fd(), data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      file.Abandon();
      throw std::runtime_error(what + " '" + file.path() + "': " + std::strerror(error));
    }
    data += n;
    left -= static_cast<size_t>(n);
  }
  file.Commit();
}

}  // namespace graspfill::io
