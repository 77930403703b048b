// SPDX-License-Identifier: BSD-3-Clause
#include "sinks/lcm_log_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/lcm_log_reader.hpp"

namespace graspfill::rt {
namespace {

// lcm's reader rejects channel names of 1000 bytes or more; LCM itself
// limits them to 255 on the bus.
constexpr size_t kMaxChannelBytes = 255;

void PutBigEndian(uint64_t v, int n, uint8_t* out) {
  for (int i = n - 1; i >= 0; --i) {
    out[i] = static_cast<uint8_t>(v & 0xff);
    v >>= 8;
  }
}

[[noreturn]] void CannotCreate(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot create log '" + path + "': " + why);
}

// What a path that is not a regular file is, for the refusal.
std::string NotRegular(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory";
  return "not a regular file (a FIFO, socket or device is never written as a log)";
}

// The folder entry of a new file reaches the disk with the folder's next
// flush; flushed now, a power cut cannot lose the whole log's name.
void SyncFolderOf(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: the file itself is written either way
  ::fsync(fd);
  ::close(fd);
}

// Creates the log at its final name: exclusively, or (overwrite) over a
// regular file only, never opening a FIFO or a device for writing.
int CreateInPlace(const std::string& path, bool overwrite) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    CannotCreate(path, NotRegular(st.st_mode));
  }
  if (!overwrite) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST) {
      CannotCreate(path, "file exists (pass overwrite to replace it)");
    }
    if (fd < 0) CannotCreate(path, std::strerror(errno));
    return fd;
  }
  // O_NONBLOCK: a FIFO that appeared since the stat does not block the
  // open; nothing is truncated before fstat says the file is regular.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_NONBLOCK | O_CLOEXEC, 0666);
  if (fd < 0) CannotCreate(path, errno == EISDIR ? "is a directory" : std::strerror(errno));
  struct stat opened {};
  if (::fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode)) {
    ::close(fd);
    CannotCreate(path, NotRegular(opened.st_mode));
  }
  if (::ftruncate(fd, 0) != 0 || ::fcntl(fd, F_SETFL, 0) != 0) {
    const int error = errno;
    ::close(fd);
    CannotCreate(path, std::strerror(error));
  }
  return fd;
}

// Writes all of `iov` (partial writes and EINTR retried); false with errno
// set on failure.
bool WriteAll(int fd, struct iovec* iov, int count) {
  while (count > 0) {
    const ssize_t n = ::writev(fd, iov, count);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) {
      errno = EIO;
      return false;
    }
    auto left = static_cast<size_t>(n);
    while (count > 0 && left >= iov->iov_len) {
      left -= iov->iov_len;
      ++iov;
      --count;
    }
    if (count > 0) {
      iov->iov_base = static_cast<uint8_t*>(iov->iov_base) + left;
      iov->iov_len -= left;
    }
  }
  return true;
}

}  // namespace

LcmLogWriter::LcmLogWriter(const std::string& path, bool overwrite)
    : LcmLogWriter(path, Options{overwrite, Mode::kAtomic}) {}

LcmLogWriter::LcmLogWriter(const std::string& path, const Options& options)
    : path_(path), mode_(options.mode) {
  if (mode_ == Mode::kInPlace) {
    fd_ = CreateInPlace(path, options.overwrite);
    SyncFolderOf(path);
    return;
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) CannotCreate(path, "is a directory");
  if (!options.overwrite && (std::filesystem::exists(path, ec) || std::filesystem::is_symlink(path, ec))) {
    CannotCreate(path, "file exists (pass overwrite to replace it)");
  }
  atomic_ = std::make_unique<io::AtomicFile>(path, "cannot create log", io::ReplaceIf(options.overwrite));
  fd_ = atomic_->fd();
}

LcmLogWriter::~LcmLogWriter() {
  if (fd_ < 0) return;
  if (mode_ == Mode::kAtomic && std::uncaught_exceptions() > uncaught_at_start_) {
    fd_ = -1;
    atomic_->Abandon();
    return;
  }
  try {
    Close();
  } catch (const std::exception& e) {
    // A destructor cannot throw. kAtomic: the temporary file is gone and
    // the path untouched; kInPlace: the log keeps what reached it. Callers
    // that must know call Close().
    std::fprintf(stderr, "graspfill: %s\n", e.what());
  }
}

void LcmLogWriter::CheckOpen() const {
  if (fd_ < 0) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': " + (failed_ ? "an earlier write failed" : "closed"));
  }
}

void LcmLogWriter::Fail(int error) {
  failed_ = true;
  if (mode_ == Mode::kAtomic) {
    fd_ = -1;
    atomic_->Abandon();
  } else {
    // Back to the last whole event (a partial one may have reached the
    // file), then closed: the log stays readable and playable.
    if (::ftruncate(fd_, bytes_written_) == 0) ::fdatasync(fd_);
    ::close(fd_);
    fd_ = -1;
  }
  throw std::runtime_error("cannot write log '" + path_ + "': " + std::strerror(error));
}

void LcmLogWriter::Write(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
  if (channel.empty() || channel.size() > kMaxChannelBytes) {
    throw std::runtime_error("cannot write log '" + path_ + "': bad channel name '" + channel + "'");
  }
  if (static_cast<int64_t>(bytes.size()) > io::kMaxLogEventDataBytes) {
    throw std::runtime_error("cannot write log '" + path_ + "': an event of " + std::to_string(bytes.size()) +
                             " bytes (readers take at most " + std::to_string(io::kMaxLogEventDataBytes) +
                             ")");
  }
  CheckOpen();
  // lcm-logger's event: sync word, event number (from 0), timestamp,
  // channel and data lengths (big-endian), channel, data.
  uint8_t header[io::kLogEventHeaderBytes];
  PutBigEndian(io::kLogEventSync, 4, header);
  PutBigEndian(static_cast<uint64_t>(events_written_), 8, header + 4);
  PutBigEndian(static_cast<uint64_t>(utime), 8, header + 12);
  PutBigEndian(channel.size(), 4, header + 20);
  PutBigEndian(bytes.size(), 4, header + 24);
  struct iovec iov[3] = {{header, sizeof(header)},
                         {const_cast<char*>(channel.data()), channel.size()},
                         {const_cast<uint8_t*>(bytes.data()), bytes.size()}};
  if (!WriteAll(fd_, iov, 3)) Fail(errno);
  bytes_written_ += static_cast<int64_t>(sizeof(header) + channel.size() + bytes.size());
  ++events_written_;
}

void LcmLogWriter::Flush() {
  CheckOpen();
  if (::fdatasync(fd_) != 0) Fail(errno);
}

void LcmLogWriter::Close() {
  CheckOpen();
  if (mode_ == Mode::kAtomic) {
    fd_ = -1;
    atomic_->Commit();  // fsync, rename; throws naming the path
    return;
  }
  Flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    throw std::runtime_error("cannot write log '" + path_ + "': " + std::strerror(errno));
  }
}

}  // namespace graspfill::rt
