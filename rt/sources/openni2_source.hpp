// SPDX-License-Identifier: BSD-3-Clause
// Depth frames from an OpenNI2 camera (PrimeSense, Kinect v1 through
// libfreenect's driver, Asus Xtion, Orbbec) or from an OpenNI2 recording
// (.oni file).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "sources/frame_source.hpp"

namespace graspfill::rt {

/// Opens one OpenNI2 device or .oni file and reads its depth stream.
///
/// Depth is converted to meters (0 = no return) and tagged with pinhole
/// intrinsics derived from the stream's field of view (principal point at
/// the image centre, (w-1)/2 and (h-1)/2), which is what OpenNI2 exposes;
/// use a calibrated model downstream where accuracy matters.
///
/// Not thread safe: one thread (the capture thread) constructs the source
/// and calls Next(). OpenNI2 itself is initialized per source and shut down
/// with it (OpenNI2 reference-counts initialize/shutdown).
class OpenNI2Source : public FrameSource {
 public:
  /// Units the device reports depth in (a device mode, not a conversion:
  /// frames always come out in meters).
  enum class DepthMode {
    k1mm,    ///< PIXEL_FORMAT_DEPTH_1_MM, range up to 65 m
    k100um,  ///< PIXEL_FORMAT_DEPTH_100_UM, finer, range up to 6.5 m
  };

  /// Pinhole parameters that replace what the device reports (each one
  /// given replaces its own; the field of view, when given, sets fx and fy
  /// as tan(fov/2) = (size/2)/f, and an explicit fx or fy wins over it).
  struct IntrinsicsOverride {
    std::optional<double> fx, fy, cx, cy;      ///< [pixels]
    std::optional<double> hfov_deg, vfov_deg;  ///< [degrees], in (0, 180)
    bool any() const { return fx || fy || cx || cy || hfov_deg || vfov_deg; }
  };

  struct Config {
    /// Device URI as OpenNI2 lists it; "" opens any device; a path ending
    /// in ".oni" opens a recording; "graspfill-replay:LOG" a graspfill
    /// recording through the replay driver (docs/openni2.md).
    std::string uri;
    /// Depth units requested from a device (a recording keeps its own).
    DepthMode depth_mode{DepthMode::k1mm};
    /// Video mode requested from a device [pixels, frames/s]; 0 = any: the
    /// device's current mode if it fits what is given (and depth_mode),
    /// else the first it lists that does. A mode the device does not have
    /// is an error that lists those it has. Ignored for recordings.
    int width{0};
    int height{0};
    int fps{0};
    /// Replaces the intrinsics the device reports.
    IntrinsicsOverride intrinsics;
    /// How long Next() waits for a frame [ms].
    int timeout_ms{2000};
    /// Recordings: true plays at the recorded rate, false hands out every
    /// frame as fast as Next() is called (no frame is skipped).
    bool realtime_playback{false};
    /// graspfill-replay devices: 1 serves frames at the recorded rate, 0 as
    /// fast as Next() is called; never is a frame skipped.
    float replay_speed{1.0f};
  };

  /// Opens the device or recording and starts its depth stream.
  /// @throws std::runtime_error naming the device and OpenNI2's own error
  ///   text when initialization, opening (e.g. "no devices found"),
  ///   the depth stream or the video mode fails.
  explicit OpenNI2Source(const Config& config);
  ~OpenNI2Source() override;
  OpenNI2Source(const OpenNI2Source&) = delete;
  OpenNI2Source& operator=(const OpenNI2Source&) = delete;

  /// Waits up to Config::timeout_ms for the next depth frame.
  ///
  /// frame->utime is the host's wall clock at reception [us since epoch]
  /// for a camera, and the device's timestamp [us] for a recording (from 0
  /// at its first frame) and for a graspfill-replay device (the recorded
  /// utime). The intrinsics: a graspfill-replay device's exact ones, else
  /// from the stream's field of view with the principal point at the image
  /// centre, then Config::intrinsics.
  /// @return kOk; kBadFrame (reason in last_error()) on a timeout or an
  ///   unusable frame; kEndOfStream after a recording's or a replay
  ///   device's last frame.
  FrameResult Next(DepthFrame* frame);
  /// As Next(DepthFrame*), as a depth event (event->error on kBadFrame).
  FrameResult Next(SourceEvent* event) override;

  /// Records the depth stream into an .oni file (OpenNI2's recorder) from
  /// now on, every frame Next() reads, until the source is destroyed.
  /// @throws std::runtime_error naming the file when OpenNI2 cannot.
  void StartRecording(const std::string& oni_path);

  /// Why the last Next() returned kBadFrame.
  const std::string& last_error() const;
  /// True when reading a recording rather than a live device.
  bool is_recording() const;
  /// True when frames come as fast as Next() asks (a recording without
  /// realtime_playback, a replay device at speed 0): a caller that must not
  /// lose frames waits for room downstream before asking for the next.
  bool paced_by_reader() const;
  /// The video mode in use, e.g. "640x480@30/1mm".
  std::string mode_text() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::rt
