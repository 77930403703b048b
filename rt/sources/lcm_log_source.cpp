#include "sources/lcm_log_source.hpp"

#include <lcm/lcm-cpp.hpp>

#include "sources/session_overrides.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace graspfill::rt {
namespace {

// Every event in an LCM log starts with this sync word (big-endian).
constexpr uint8_t kLogMagic[4] = {0xED, 0xA1, 0xDA, 0x01};
// Bytes of an event header after the sync word: eventnum, timestamp,
// channel length, data length.
constexpr int64_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;

[[noreturn]] void CannotOpen(const std::string& path, const std::string& why) {
  throw std::runtime_error("cannot open log '" + path + "': " + why);
}

}  // namespace

LcmLogSource::LcmLogSource(const Config& config) : config_(config), T_C_B_(config.T_C_B) {
  const std::string& path = config_.path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) CannotOpen(path, "no such file");
  if (std::filesystem::is_directory(path, ec)) {
    CannotOpen(path, "is a directory");
  }
  // Check the first sync word ourselves: lcm's reader would silently scan
  // any file for one and report an empty log.
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) CannotOpen(path, std::strerror(errno));
    uint8_t magic[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(magic), sizeof(magic));
    const std::streamsize got = in.gcount();
    if (got != 0 && (got != 4 || !std::equal(magic, magic + 4, kLogMagic))) {
      throw std::runtime_error("'" + path +
                               "' is not an LCM log (no event sync word at "
                               "the start of the file)");
    }
  }
  file_size_ = static_cast<int64_t>(std::filesystem::file_size(path, ec));
  if (ec) CannotOpen(path, ec.message());
  log_ = std::make_unique<lcm::LogFile>(path, "r");
  if (!log_->good()) CannotOpen(path, std::strerror(errno));
}

LcmLogSource::~LcmLogSource() = default;

FrameResult LcmLogSource::Next(SourceEvent* event) {
  while (!ended_) {
    FILE* file = log_->getFilePtr();
    const int64_t start = ftello(file);
    const lcm::LogEvent* log_event = log_->readNextEvent();
    if (log_event == nullptr) {
      // lcm returns null both at a clean end and on a cut or corrupt
      // event; only the former leaves nothing unread.
      ended_ = true;
      if (start < file_size_) truncated_ = true;
      break;
    }
    ++events_read_;
    // lcm checks that a sync word follows each event, but a sync word cut
    // short at the end of the file is consumed without complaint: catch it
    // by the event's expected size.
    const int64_t end = ftello(file);
    if (end == file_size_ &&
        end - start > kEventHeaderBytes +
                          static_cast<int64_t>(log_event->channel.size()) +
                          log_event->datalen) {
      truncated_ = true;
    }

    const std::string& channel = log_event->channel;
    if (std::find(channels_seen_.begin(), channels_seen_.end(), channel) ==
        channels_seen_.end()) {
      channels_seen_.push_back(channel);
    }
    const size_t size = static_cast<size_t>(log_event->datalen);
    if (channel == config_.channels.depth) {
      event->kind = SourceEvent::Kind::kDepth;
      if (!io::DecodeDepthImage(log_event->data, size, &event->depth,
                                &event->error) ||
          !ApplyIntrinsicsOverride(intrinsics_, &event->depth, &event->error)) {
        return FrameResult::kBadFrame;
      }
      return FrameResult::kOk;
    }
    if (channel == config_.channels.gripper_state) {
      event->kind = SourceEvent::Kind::kGripperState;
      if (!io::DecodeGripperState(log_event->data, size, T_C_B_,
                                  &event->gripper, &event->error)) {
        return FrameResult::kBadFrame;
      }
      return FrameResult::kOk;
    }
    if (channel == config_.channels.session) {
      event->kind = SourceEvent::Kind::kSession;
      if (!io::DecodeSessionDescription(log_event->data, size, &event->session,
                                        &event->error)) {
        return FrameResult::kBadFrame;
      }
      ++sessions_read_;
      if (config_.T_C_B_from_session) T_C_B_ = event->session.T_C_B;
      if (config_.intrinsics_from_session) intrinsics_ = event->session.intrinsics;
      if (config_.session_events) return FrameResult::kOk;
      continue;
    }
    ++skipped_other_channels_;
  }
  return FrameResult::kEndOfStream;
}

}  // namespace graspfill::rt
