// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/io/lcm_log_reader.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "graspfill/core/regular_file.hpp"

namespace graspfill::io {
namespace {

[[noreturn]] void CannotOpen(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot open log '" + path + "': " + why);
}

uint64_t BigEndian(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : owns_file_(true), name_(path) {
  // fopen of a FIFO blocks until a writer appears: look before opening.
  if (const std::string why = NotARegularFile(path); !why.empty()) CannotOpen(path, why);
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) CannotOpen(path, std::strerror(errno));
  struct stat opened {};
  if (::fstat(fileno(file_), &opened) != 0 || !S_ISREG(opened.st_mode)) {
    std::fclose(file_);
    CannotOpen(path, "not a regular file");
  }
  size_ = static_cast<int64_t>(opened.st_size);
  if (size_ > 0) {
    uint8_t magic[4] = {0, 0, 0, 0};
    const size_t got = std::fread(magic, 1, sizeof(magic), file_);
    std::rewind(file_);
    if (got != 4 || BigEndian(magic, 4) != kLogEventSync) {
      std::fclose(file_);
      throw std::runtime_error("'" + path +
                               "' is not an LCM log (no event sync word at "
                               "the start of the file)");
    }
  }
}

LcmLogReader::LcmLogReader(std::FILE* file, int64_t size, std::string name)
    : file_(file), size_(size < 0 ? 0 : size), name_(std::move(name)) {}

LcmLogReader::~LcmLogReader() {
  if (owns_file_ && file_ != nullptr) std::fclose(file_);
}

LogReadResult LcmLogReader::Stop(LogReadResult result, const std::string& why) {
  stopped_ = true;
  stop_result_ = result;
  if (!why.empty()) {
    error_ = "log '" + name_ + "', event at byte " + std::to_string(offset_) + ": " + why;
  }
  return result;
}

LogReadResult LcmLogReader::Next(LogEvent* event) {
  if (stopped_) return stop_result_;
  const int64_t left = size_ - offset_;
  if (left == 0) return Stop(LogReadResult::kEnd, "");
  if (left < kLogEventHeaderBytes) {
    return Stop(LogReadResult::kTruncated, "header cut short (" + std::to_string(left) + " of " +
                                               std::to_string(kLogEventHeaderBytes) + " bytes)");
  }
  uint8_t header[kLogEventHeaderBytes];
  if (std::fread(header, 1, sizeof(header), file_) != sizeof(header)) {
    return Stop(LogReadResult::kTruncated, "read failed in the header");
  }
  if (BigEndian(header, 4) != kLogEventSync) {
    return Stop(LogReadResult::kCorrupt, "no sync word");
  }
  const auto event_number = static_cast<int64_t>(BigEndian(header + 4, 8));
  const auto timestamp = static_cast<int64_t>(BigEndian(header + 12, 8));
  const auto channel_bytes = static_cast<int32_t>(static_cast<uint32_t>(BigEndian(header + 20, 4)));
  const auto data_bytes = static_cast<int32_t>(static_cast<uint32_t>(BigEndian(header + 24, 4)));
  if (channel_bytes <= 0 || channel_bytes > kMaxLogChannelBytes) {
    return Stop(LogReadResult::kCorrupt, "channel length " + std::to_string(channel_bytes) + " outside 1.." +
                                             std::to_string(kMaxLogChannelBytes));
  }
  if (data_bytes < 0 || data_bytes > kMaxLogEventDataBytes) {
    return Stop(LogReadResult::kCorrupt, "data length " + std::to_string(data_bytes) + " outside 0.." +
                                             std::to_string(kMaxLogEventDataBytes));
  }
  // Checked against the file before anything is allocated or read.
  const int64_t body = int64_t{channel_bytes} + data_bytes;
  if (body > left - kLogEventHeaderBytes) {
    return Stop(LogReadResult::kTruncated,
                "declares " + std::to_string(body) + " bytes of channel and data, " +
                    std::to_string(left - kLogEventHeaderBytes) + " left in the file");
  }
  event->channel.resize(static_cast<size_t>(channel_bytes));
  event->data.resize(static_cast<size_t>(data_bytes));
  if (std::fread(event->channel.data(), 1, event->channel.size(), file_) != event->channel.size() ||
      std::fread(event->data.data(), 1, event->data.size(), file_) != event->data.size()) {
    return Stop(LogReadResult::kTruncated, "read failed in the event body");
  }
  event->event_number = event_number;
  event->timestamp_us = timestamp;
  offset_ += kLogEventHeaderBytes + body;
  return LogReadResult::kEvent;
}

}  // namespace graspfill::io
