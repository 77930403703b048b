// Temporary file + fsync + rename (POSIX rename replaces the target
// atomically within one file system, which the temporary file's place in
// the target's folder guarantees).
#include "graspfill/io/atomic_file.hpp"

#include <fcntl.h>
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
    const auto ticks = static_cast<unsigned long long>(
        std::chrono::steady_clock::now().time_since_epoch().count());
    char suffix[32];
    std::snprintf(suffix, sizeof(suffix), "%06llx",
                  (ticks ^ (static_cast<unsigned long long>(::getpid()) << 20) ^
                   (static_cast<unsigned long long>(counter++) << 8)) & 0xffffffULL);
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

}  // namespace internal

AtomicFile::AtomicFile(const std::string& path, const std::string& what)
    : what_(what), path_(internal::FollowSymlinks(path)) {
  fd_ = internal::CreateTempFile(path_, &temp_path_);
  if (fd_ < 0) {
    const int error = errno;
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
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
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp_path_.c_str());
    throw std::runtime_error(what_ + " '" + path_ + "': " + std::strerror(error));
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

void WriteFileAtomically(const std::string& path, const std::string& bytes,
                         const std::string& what) {
  AtomicFile file(path, what);
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
