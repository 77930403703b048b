// SPDX-License-Identifier: BSD-3-Clause
// Replays a recorded LCM log (lcm-logger's format) as source events: depth
// images and gripper states on graspfill's channels, decoded as they are
// read, and the session description (session_description_t, at the head of
// the recordings graspfill writes), which also sets the hand-eye calibration
// and the intrinsics override for the events after it. Events on other
// channels are skipped and counted.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "graspfill/io/lcm_log_reader.hpp"
#include "graspfill/io/messages.hpp"
#include "sources/frame_source.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill::rt {

/// Reads an LCM log file event by event, in file order, as fast as asked:
/// pacing (real time or faster) is the caller's business, using the
/// messages' utime.
///
/// Not thread safe: one thread calls Next() and the accessors.
class LcmLogSource : public FrameSource {
 public:
  struct Config {
    /// Path of the log file.
    std::string path;
    /// Channels carrying depth_image_t, gripper_state_t and
    /// session_description_t.
    io::ChannelNames channels;
    /// Hand-eye, intrinsics and clock offset over the session descriptions'.
    SourceOverrides overrides;
    /// Hand session descriptions to the caller as SourceEvent::Kind::kSession
    /// events (false: they are read and applied as above, not returned).
    bool session_events{false};
    /// Depth images with more pixels are bad frames (kBadSize), refused
    /// before their decoded size is allocated (a rig config's
    /// camera.max_depth_pixels; io::DecodeDepthImage).
    int64_t max_depth_pixels{io::kDefaultMaxDepthPixels};
  };

  /// Opens the log.
  /// @throws std::runtime_error "cannot open log '<path>': <reason>" if the
  ///   file is missing, a directory, not a regular file (a FIFO) or
  ///   unreadable, and "'<path>' is not an
  ///   LCM log ..." if it does not start with an LCM event header. An empty
  ///   file is a log with no events.
  explicit LcmLogSource(const Config& config);
  ~LcmLogSource() override;
  LcmLogSource(const LcmLogSource&) = delete;
  LcmLogSource& operator=(const LcmLogSource&) = delete;

  /// Reads events until one on the depth or gripper-state channel (or the
  /// session channel, with Config::session_events).
  /// @return kOk with event->kind and the decoded member set; kBadFrame with
  ///   event->kind and event->error when that event does not decode (a
  ///   session description too, even without session_events; a depth image
  ///   whose size differs from the session's intrinsics override) (the next
  ///   call goes on with the following event); kEndOfStream at the end of
  ///   the file or where the file stops making sense (see truncated()).
  FrameResult Next(SourceEvent* event) override;

  /// True once reading stopped before the end of the file: the last event
  /// is cut short (a log copied while being written, a full disk) or the
  /// bytes after an event are not an event.
  bool truncated() const { return truncated_; }
  /// True when reading stopped at a partial last event (a recording cut by
  /// a crash, a kill, a power cut or a full disk): every event before it
  /// was whole and was read; a note for the caller, not an error. False for
  /// bytes that are not an event (corrupt), which truncated() also flags.
  bool partial_last_event() const { return partial_last_event_; }
  /// Bytes after the last whole event that were not read (the partial
  /// event, or from the corrupt bytes on).
  int64_t unread_bytes() const { return reader_->file_size() - reader_->offset(); }
  /// Why reading stopped early (see truncated()), naming the file, the
  /// byte offset and the field; "" otherwise.
  const std::string& stop_reason() const { return reader_->error(); }
  /// Events read from the file so far, on every channel.
  int64_t events_read() const { return events_read_; }
  /// Events skipped because they were on none of our channels.
  int64_t skipped_other_channels() const { return skipped_other_channels_; }
  /// Every channel seen so far, in order of first appearance.
  std::vector<std::string> channels_seen() const { return channels_seen_; }
  /// Session descriptions decoded so far.
  int64_t sessions_read() const { return sessions_read_; }

 private:
  Config config_;
  std::unique_ptr<io::LcmLogReader> reader_;  // bounded: never trusts a declared length
  io::LogEvent log_event_;                    // reused
  bool ended_{false};
  bool truncated_{false};
  bool partial_last_event_{false};
  int64_t events_read_{0};
  int64_t skipped_other_channels_{0};
  std::vector<std::string> channels_seen_;
  int64_t sessions_read_{0};
  // What the last session description set (see Config).
  Eigen::Isometry3d T_C_B_{Eigen::Isometry3d::Identity()};
  std::optional<CameraIntrinsics> intrinsics_;
};

}  // namespace graspfill::rt
