// SPDX-License-Identifier: BSD-3-Clause
// The one loop that feeds a session from its source: replay (a log), live
// (an OpenNI2 device or .oni file; or the LCM bus, which pushes on its own
// thread while the loop only keeps time), record and bench all run it.
// Events go to an EventSink (a GraspSequencer on this thread, the threaded
// GraspModule, a recorder beside it); the loop owns the stop rules
// (interrupt, duration, idle) and a periodic tick (the status).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

#include "sources/frame_source.hpp"

namespace graspfill::rt {

/// Where a session's events go.
class EventSink {
 public:
  virtual ~EventSink() = default;
  /// An event the source produced. Return false to stop the loop.
  virtual bool OnEvent(const SourceEvent& event) = 0;
  /// An event the source could not produce (event.kind and event.error
  /// say which and why). Return false to stop the loop.
  virtual bool OnBadEvent(const SourceEvent& event) = 0;
};

struct SessionLoopLimits {
  /// Set (e.g. by a signal handler) to stop; may be null.
  const std::atomic<bool>* interrupted{nullptr};
  /// Stop after this long [s]; 0 = no limit.
  double duration_s{0.0};
  /// Stop when no depth frame came for this long after the first [s];
  /// 0 = never.
  double idle_exit_s{0.0};
  /// Called between events, about every tick_ms (the status), on the
  /// loop's thread.
  std::function<void()> on_tick;
  int tick_ms{1000};
  /// Without a source: how long to sleep between looks at the clock [ms].
  int poll_ms{10};
};

enum class LoopEnd { kEndOfStream, kSinkStopped, kInterrupted, kDuration, kIdle };

class SessionLoop {
 public:
  explicit SessionLoop(SessionLoopLimits limits);

  /// Feeds `sink` from `source` until it ends or a limit stops the loop.
  /// With a null source the events come another way (the bus's thread
  /// calls the sink, and NoteDepthFrame for the idle rule): the loop only
  /// ticks and watches the limits.
  LoopEnd Run(FrameSource* source, EventSink* sink);

  /// A depth frame arrived (any thread): restarts the idle timer.
  void NoteDepthFrame();

 private:
  using Clock = std::chrono::steady_clock;
  // The reason to stop now, or kEndOfStream for none.
  LoopEnd Limit(Clock::time_point now) const;

  SessionLoopLimits limits_;
  Clock::time_point start_;
  std::atomic<int64_t> last_depth_ns_{0};  // steady clock; 0 = none yet
};

}  // namespace graspfill::rt
