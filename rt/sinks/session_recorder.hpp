// SPDX-License-Identifier: BSD-3-Clause
// Records what a live session received (`graspfill live --record LOG`): the
// session description first, then every depth frame and gripper state as it
// arrived, as an LCM log that `graspfill replay` and `lcm-logplayer` play.
// Off the frame path: Record() copies the event into a slot of a bounded
// ring and returns; a writer thread encodes and writes. When the writer
// falls behind, the newest event is dropped and counted (the log then
// misses it: dropped() says so; a replay of it is not the session).
//
// Memory: the ring is bounded in events (queue_capacity) and in bytes
// (queue_bytes: the buffers its slots hold, depth at 4 bytes a pixel). A
// frame that does not fit takes the buffer of a free slot that does, else
// the free slots give their buffers back; if the queued events alone leave
// no room it is dropped (counted). One event is always admitted when none
// waits, so the ring holds at most max(queue_bytes, the largest event);
// the writer's copy of the event it writes, and its encoding, come on top
// (about 2 frames).
//
// The log survives what ends a process (LcmLogWriter::Mode::kInPlace): it
// is written at its final name from the start, each event with one
// write(2), and made durable (fdatasync) every sync_period_ms. A write that
// fails (a full disk) stops the recording: the log keeps the events written
// before it (whole: readable and playable), stderr says so once, failure()
// tells it, and later events are dropped (counted); the session goes on.
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
    /// Replace an existing regular file (never a FIFO, device or folder).
    bool overwrite{false};
    io::ChannelNames channels;
    /// Events waiting for the writer, at most.
    int queue_capacity{64};
    /// Bytes the waiting events' buffers may hold, at least 1 MiB. 256 MiB:
    /// the 64 slots of 1280 x 720 frames (3.7 MB each) fit; of 4096 x 4096
    /// frames (67 MB), 3.
    int64_t queue_bytes{int64_t{256} << 20};
    /// What was written is made durable (fdatasync) at least this often
    /// [ms], so a power cut loses at most the last period's events; 0:
    /// after every event.
    int sync_period_ms{1000};
  };

  /// Creates the log (at its final name, exclusively unless overwrite) and
  /// starts the writer. `session` is written first, stamped with the first
  /// event's utime. Throws std::runtime_error naming the path.
  SessionRecorder(const Config& config, const io::SessionDescription& session);
  /// Closes (as Close); errors go to stderr.
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  /// Queues a depth or gripper-state event (others are ignored). Never
  /// waits for the disk.
  void Record(const SourceEvent& event);
  void RecordDepth(const DepthFrame& frame);
  void RecordGripperState(const GripperState& state);

  /// Writes what is queued and closes the log. After a failed write (see
  /// failure()) it only stops the writer: the log was closed then.
  /// Throws std::runtime_error (naming the path) if closing fails.
  void Close();

  int64_t events_written() const;
  int64_t events_dropped() const;
  /// Why the recording stopped early (the write error, naming the path and
  /// the system's reason); "" while it goes on.
  std::string failure() const;
  /// Bytes the ring's slots hold now, and the most they held.
  int64_t queue_bytes() const;
  int64_t queue_bytes_peak() const;
  const std::string& path() const { return config_.path; }

 private:
  void WriterLoop();
  // Lock held: the slot for the next event, or null when the event is
  // dropped (full, closed or failed; counted).
  SourceEvent* Reserve();
  // Lock held: makes room in the budget for `slot` to hold `depth_values`
  // floats and `joint_values` doubles; false if the queued events leave
  // none (the caller drops the event).
  bool MakeRoom(size_t slot, size_t depth_values, size_t joint_values);
  void ReleaseBuffers(SourceEvent* slot);
  // Lock held: a failed write stops the recording (see the file comment).
  void StopAfterFailure(const std::string& why);

  Config config_;
  io::SessionDescription session_;
  std::unique_ptr<LcmLogWriter> writer_;

  mutable std::mutex mutex_;
  std::condition_variable wake_writer_;
  std::vector<SourceEvent> slots_;  // ring, buffers reused
  size_t head_{0}, count_{0};
  int64_t slot_bytes_{0}, slot_bytes_peak_{0};  // the slots' buffers
  bool stop_{false}, closed_{false};
  int64_t written_{0}, dropped_{0};
  std::string failure_;  // the writer's error, "" if none
  std::thread thread_;   // last
};

}  // namespace graspfill::rt
