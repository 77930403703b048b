// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/core/regular_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace graspfill {
namespace {

std::string ModeDefect(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory";
  if (!S_ISREG(mode)) return "not a regular file (a FIFO, socket or device: it could block or never end)";
  return "";
}

std::string SystemReason(int error) {
  return error == ENOENT ? std::string("no such file") : std::string(std::strerror(error));
}

// Closes the descriptor on every way out.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string NotARegularFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return SystemReason(errno);
  return ModeDefect(st.st_mode);
}

std::string ReadRegularFile(const std::string& path, int64_t max_bytes, const std::string& what) {
  const auto fail = [&](const std::string& why) -> std::runtime_error {
    return std::runtime_error(what + " '" + path + "': " + why);
  };
  if (const std::string why = NotARegularFile(path); !why.empty()) throw fail(why);
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  const Descriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) throw fail(SystemReason(errno));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) throw fail(SystemReason(errno));
  if (const std::string why = ModeDefect(st.st_mode); !why.empty()) throw fail(why);
  if (st.st_size > max_bytes) {
    throw fail("larger than " + std::to_string(max_bytes) + " bytes (" +
               std::to_string(static_cast<int64_t>(st.st_size)) + " bytes)");
  }
  std::string bytes(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw fail(SystemReason(errno));
    if (n == 0) break;  // the file shrank while being read: what is there
    done += static_cast<size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace graspfill
