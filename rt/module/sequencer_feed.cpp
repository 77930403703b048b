// SPDX-License-Identifier: BSD-3-Clause
#include "module/sequencer_feed.hpp"

#include <cmath>
#include <utility>

namespace graspfill::rt {

SequencerFeed::SequencerFeed(Factory factory, bool skip_bad)
    : factory_(std::move(factory)), skip_bad_(skip_bad) {}

bool SequencerFeed::Bad(const std::string& error) {
  ++bad_events_;
  if (first_error_.empty()) first_error_ = error;
  return skip_bad_;
}

bool SequencerFeed::OnEvent(const SourceEvent& event) {
  if (event.kind == SourceEvent::Kind::kSession) {
    ++sessions_;
    if (!sequencer_ && !session_) {
      session_ = event.session;
    } else {
      if (late_sessions_ == 0) late_session_utime_ = event.session.utime;
      ++late_sessions_;
    }
    return true;
  }
  if (!sequencer_) sequencer_ = factory_(session_);
  if (event.kind == SourceEvent::Kind::kDepth) {
    ++depth_events_;
    if (sequencer_->AddDepthFrame(event.depth, &error_) != FrameOutcome::kBadFrame) return true;
    return Bad("depth frame at utime " + std::to_string(event.depth.utime) + ": " + error_);
  }
  if (sequencer_->AddGripperState(event.gripper)) return true;
  // Out-of-order states are benign; non-finite poses are bad input.
  if (event.gripper.T_C_G.matrix().allFinite() && std::isfinite(event.gripper.opening_m)) {
    return true;
  }
  return Bad("gripper state at utime " + std::to_string(event.gripper.utime) +
             ": non-finite pose or opening");
}

bool SequencerFeed::OnBadEvent(const SourceEvent& event) { return Bad(event.error); }

}  // namespace graspfill::rt
