// SPDX-License-Identifier: BSD-3-Clause
// An EventSink that fuses on the loop's own thread: events into a
// GraspSequencer made at the first depth or gripper event, once the session
// description at the head of a recording (if any) is known. Replay and bench
// use it; what counts as a bad event is decided here once for both.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"
#include "module/grasp_sequencer.hpp"
#include "module/session_loop.hpp"

namespace graspfill::rt {

class SequencerFeed : public EventSink {
 public:
  /// Makes the sequencer from the session description that came before the
  /// first depth or gripper event (none if there was none). May throw: the
  /// exception leaves Run through OnEvent.
  using Factory =
      std::function<std::unique_ptr<GraspSequencer>(const std::optional<io::SessionDescription>&)>;

  /// @param skip_bad  count malformed events and go on (else the first one
  ///   stops the loop; error() says which).
  SequencerFeed(Factory factory, bool skip_bad);

  bool OnEvent(const SourceEvent& event) override;
  bool OnBadEvent(const SourceEvent& event) override;

  /// Null until the first depth or gripper event.
  GraspSequencer* sequencer() { return sequencer_.get(); }
  const GraspSequencer* sequencer() const { return sequencer_.get(); }
  /// The first session description, if it came before the first event.
  const std::optional<io::SessionDescription>& session() const { return session_; }
  int64_t sessions() const { return sessions_; }
  /// Session descriptions after the first one or after the first event
  /// (their claw, box and voxel are not used).
  int64_t late_sessions() const { return late_sessions_; }
  int64_t late_session_utime() const { return late_session_utime_; }
  int64_t depth_events() const { return depth_events_; }
  int64_t bad_events() const { return bad_events_; }
  /// The first bad event, as a sentence ("" if none).
  const std::string& first_error() const { return first_error_; }

 private:
  bool Bad(const std::string& error);

  Factory factory_;
  bool skip_bad_;
  std::unique_ptr<GraspSequencer> sequencer_;
  std::optional<io::SessionDescription> session_;
  int64_t sessions_{0}, late_sessions_{0}, late_session_utime_{0};
  int64_t depth_events_{0}, bad_events_{0};
  std::string error_, first_error_;  // error_: scratch, reused
};

}  // namespace graspfill::rt
