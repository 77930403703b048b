// SPDX-License-Identifier: BSD-3-Clause
// The depth of a live session from OpenNI2, alone or merged with a
// recording's other events: with a graspfill-replay:LOG device (or an
// explicit log, e.g. beside an .oni recorded from one), the gripper states
// and session descriptions come from the log, in time order with the
// device's depth frames, as if the robot were on the bus. What `graspfill
// live --device` reads.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "graspfill/io/messages.hpp"
#include "sources/frame_source.hpp"
#include "sources/lcm_log_source.hpp"
#include "sources/openni2_source.hpp"
#include "sources/session_overrides.hpp"

namespace graspfill::rt {

class CameraSource : public FrameSource {
 public:
  struct Config {
    OpenNI2Source::Config device;
    /// LCM log read alongside the device for gripper states and session
    /// descriptions ("" = none; a graspfill-replay:LOG device reads LOG).
    std::string log;
    /// The log's channels (its depth images are skipped: depth comes
    /// through OpenNI2).
    io::ChannelNames channels;
    /// The log's hand-eye and clock offset over its session descriptions'
    /// (LcmLogSource::Config::overrides; the intrinsics apply to no image:
    /// the depth comes through OpenNI2, see OpenNI2Source::Config).
    SourceOverrides overrides;
  };

  /// Opens the device (and the log).
  /// @throws std::runtime_error as OpenNI2Source and LcmLogSource do.
  explicit CameraSource(const Config& config);
  ~CameraSource() override;
  CameraSource(const CameraSource&) = delete;
  CameraSource& operator=(const CameraSource&) = delete;

  /// The next event: without a log, the device's next depth frame; with
  /// one, the log's first session description first, then its gripper
  /// states and sessions and the device's frames by timestamp (a state
  /// before a frame of the same time). The frames' timestamps are moved
  /// onto the log's clock when the device's start elsewhere (an .oni starts
  /// at 0): the first frame gets the utime of the log's first depth image.
  /// A session description's intrinsics override applies to the frames
  /// after it, unless the device's Config::intrinsics overrides them.
  FrameResult Next(SourceEvent* event) override;

  /// Runs `gate` before each frame is asked of a device that hands them out
  /// as fast as asked (OpenNI2Source::paced_by_reader), e.g. to wait until
  /// the consumer has room: then a recording replays without a lost frame.
  void SetFrameGate(std::function<void()> gate) { frame_gate_ = std::move(gate); }

  /// The log's session description at its head, if it has one.
  const std::optional<io::SessionDescription>& session() const { return head_session_; }
  /// The log read alongside ("" for none).
  const std::string& log() const { return config_.log; }
  OpenNI2Source& device() { return *device_; }

 private:
  bool FillCamera();
  bool FillLog();

  Config config_;
  std::unique_ptr<OpenNI2Source> device_;
  std::function<void()> frame_gate_;
  std::unique_ptr<LcmLogSource> log_;
  std::optional<io::SessionDescription> head_session_;
  bool head_session_sent_{false};
  std::optional<int64_t> log_first_depth_utime_;
  std::optional<int64_t> camera_offset_us_;              // added to the device's stamps
  std::optional<CameraIntrinsics> intrinsics_override_;  // the latest session's
  // One event read ahead from each side.
  SourceEvent camera_event_, log_event_;
  FrameResult camera_result_{FrameResult::kOk}, log_result_{FrameResult::kOk};
  bool camera_pending_{false}, log_pending_{false};
  bool camera_ended_{false}, log_ended_{false};
};

}  // namespace graspfill::rt
