// Records what a live session received (`graspfill live --record LOG`): the
// session description first, then every depth frame and gripper state as it
// arrived, as an LCM log that `graspfill replay` and `lcm-logplayer` play.
// Off the frame path: Record() copies the event into a slot of a bounded
// ring and returns; a writer thread encodes and writes. When the writer
// falls behind, the newest event is dropped and counted (the log then
// misses it: dropped() says so; a replay of it is not the session).
//
// What is written: depth as depth_image_t (ZLIB16, 1 mm units: lossless for
// OpenNI2's and graspfill's 1 mm depth), gripper states as gripper_state_t
// in the camera frame (the hand-eye T_C_B already applied, so the replay
// does not apply it again) with their grasp_id, each stamped (log time) with
// its own utime. The intrinsics the session used are the images' (a
// session description's override is already applied, and repeated in the
// recorded description: applying it again changes nothing).
//
// Threads: Record() from any thread (a short lock), Close() from one.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "graspfill/io/messages.hpp"
#include "sources/frame_source.hpp"

namespace graspfill::rt {

class LcmLogWriter;

class SessionRecorder {
 public:
  struct Config {
    std::string path;
    bool overwrite{false};
    io::ChannelNames channels;
    /// Events waiting for the writer (depth frames ~1 MB each in memory).
    int queue_capacity{64};
  };

  /// Creates the log (atomically: renamed into place by Close) and starts
  /// the writer. `session` is written first, stamped with the first
  /// event's utime. Throws std::runtime_error naming the path.
  SessionRecorder(const Config& config, const io::SessionDescription& session);
  /// Closes (as Close) unless a write failed; errors go to stderr.
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  /// Queues a depth or gripper-state event (others are ignored). Never
  /// waits for the disk.
  void Record(const SourceEvent& event);
  void RecordDepth(const DepthFrame& frame);
  void RecordGripperState(const GripperState& state);

  /// Writes what is queued, closes and renames the log into place.
  /// Throws std::runtime_error (naming the path) if a write failed.
  void Close();

  int64_t events_written() const;
  int64_t events_dropped() const;
  const std::string& path() const { return config_.path; }

 private:
  void WriterLoop();
  // Lock held: the slot for the next event, or null when full (dropped).
  SourceEvent* Reserve();

  Config config_;
  io::SessionDescription session_;
  std::unique_ptr<LcmLogWriter> writer_;

  mutable std::mutex mutex_;
  std::condition_variable wake_writer_, idle_;
  std::vector<SourceEvent> slots_;  // ring, buffers reused
  size_t head_{0}, count_{0};
  bool busy_{false}, stop_{false}, closed_{false};
  int64_t written_{0}, dropped_{0};
  std::string failure_;  // the writer's error, "" if none
  std::thread thread_;   // last
};

}  // namespace graspfill::rt
