#include "sinks/lcm_log_writer.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "graspfill/io/atomic_file.hpp"

namespace graspfill::rt {
namespace {

// lcm's reader rejects channel names of 1000 bytes or more; LCM itself
// limits them to 255 on the bus.
constexpr size_t kMaxChannelBytes = 255;

}  // namespace

LcmLogWriter::LcmLogWriter(const std::string& path, bool overwrite)
    : path_(path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw std::runtime_error("cannot create log '" + path +
                             "': is a directory");
  }
  if (!overwrite && (std::filesystem::exists(path, ec) ||
                     std::filesystem::is_symlink(path, ec))) {
    throw std::runtime_error("cannot create log '" + path +
                             "': file exists (pass overwrite to replace it)");
  }
  // Without overwrite, created only where nothing is when the log is
  // closed: of two recorders racing to one path, one fails.
  file_ = std::make_unique<io::AtomicFile>(path, "cannot create log", io::ReplaceIf(overwrite));
  // lcm opens the file by name: the temporary file, truncated (it is new).
  log_ = std::make_unique<lcm::LogFile>(file_->temp_path(), "w");
  if (!log_->good()) {
    const int error = errno;
    log_.reset();
    file_->Abandon();
    throw std::runtime_error("cannot create log '" + path +
                             "': " + std::strerror(error));
  }
}

LcmLogWriter::~LcmLogWriter() {
  if (!log_) return;
  if (std::uncaught_exceptions() > uncaught_at_start_) {
    log_.reset();
    file_->Abandon();
    return;
  }
  try {
    Close();
  } catch (const std::exception& e) {
    // A destructor cannot throw; the temporary file is gone and the path
    // untouched. Callers that must know call Close().
    std::fprintf(stderr, "graspfill: %s\n", e.what());
  }
}

void LcmLogWriter::Fail(const std::string& why) {
  log_.reset();
  if (file_) file_->Abandon();
  throw std::runtime_error("cannot write log '" + path_ + "': " + why);
}

void LcmLogWriter::Write(const std::string& channel, int64_t utime,
                         const std::vector<uint8_t>& bytes) {
  if (channel.empty() || channel.size() > kMaxChannelBytes) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': bad channel name '" + channel + "'");
  }
  if (!log_) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': closed (or an earlier write failed)");
  }
  lcm::LogEvent event;
  event.eventnum = 0;  // numbered by lcm
  event.timestamp = utime;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(bytes.size());
  // lcm's event struct is not const-correct; writeEvent only reads it.
  event.data = const_cast<uint8_t*>(bytes.data());
  errno = 0;
  if (log_->writeEvent(&event) != 0) {
    Fail(errno != 0 ? std::strerror(errno) : "write error");
  }
  ++events_written_;
}

void LcmLogWriter::Flush() {
  if (!log_) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': closed (or an earlier write failed)");
  }
  errno = 0;
  if (std::fflush(log_->getFilePtr()) != 0 || std::ferror(log_->getFilePtr())) {
    Fail(errno != 0 ? std::strerror(errno) : "write error");
  }
}

void LcmLogWriter::Close() {
  if (!log_) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': closed (or an earlier write failed)");
  }
  Flush();
  log_.reset();     // fclose: nothing is buffered after the flush
  file_->Commit();  // fsync, rename; throws naming the path
}

}  // namespace graspfill::rt
