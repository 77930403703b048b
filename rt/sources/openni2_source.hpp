// Depth frames from an OpenNI2 camera (PrimeSense, Kinect v1 through
// libfreenect's driver, Asus Xtion, Orbbec) or from an OpenNI2 recording
// (.oni file).
#pragma once

#include <memory>
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

  struct Config {
    /// Device URI as OpenNI2 lists it; "" opens any device; a path ending
    /// in ".oni" opens a recording.
    std::string uri;
    /// Depth units requested from a device (a recording keeps its own).
    DepthMode depth_mode{DepthMode::k1mm};
    /// Video mode requested from a device [pixels, frames/s]; must be one
    /// the device supports (the error lists them). Ignored for recordings.
    int width{640};
    int height{480};
    int fps{30};
    /// How long Next() waits for a frame [ms].
    int timeout_ms{2000};
    /// Recordings: true plays at the recorded rate, false hands out every
    /// frame as fast as Next() is called (no frame is skipped).
    bool realtime_playback{false};
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
  /// for a device, and the recorded device timestamp [us] for a recording.
  /// @return kOk; kBadFrame (reason in last_error()) on a timeout or an
  ///   unusable frame; kEndOfStream after a recording's last frame.
  FrameResult Next(DepthFrame* frame);
  /// As Next(DepthFrame*), as a depth event (event->error on kBadFrame).
  FrameResult Next(SourceEvent* event) override;

  /// Why the last Next() returned kBadFrame.
  const std::string& last_error() const;
  /// True when reading a recording rather than a live device.
  bool is_recording() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspfill::rt
