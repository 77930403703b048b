#include "sinks/lcm_log_writer.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

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
  if (!overwrite && std::filesystem::exists(path, ec)) {
    throw std::runtime_error("cannot create log '" + path +
                             "': file exists (pass overwrite to replace it)");
  }
  log_ = std::make_unique<lcm::LogFile>(path, "w");
  if (!log_->good()) {
    throw std::runtime_error("cannot create log '" + path +
                             "': " + std::strerror(errno));
  }
}

LcmLogWriter::~LcmLogWriter() = default;

void LcmLogWriter::Write(const std::string& channel, int64_t utime,
                         const std::vector<uint8_t>& bytes) {
  if (channel.empty() || channel.size() > kMaxChannelBytes) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': bad channel name '" + channel + "'");
  }
  lcm::LogEvent event;
  event.eventnum = 0;  // numbered by lcm
  event.timestamp = utime;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(bytes.size());
  // lcm's event struct is not const-correct; writeEvent only reads it.
  event.data = const_cast<uint8_t*>(bytes.data());
  if (log_->writeEvent(&event) != 0) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': " + std::strerror(errno));
  }
  ++events_written_;
}

void LcmLogWriter::Flush() {
  if (std::fflush(log_->getFilePtr()) != 0) {
    throw std::runtime_error("cannot write log '" + path_ +
                             "': " + std::strerror(errno));
  }
}

}  // namespace graspfill::rt
