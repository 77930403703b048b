// SPDX-License-Identifier: BSD-3-Clause
#include "sources/openni2_source.hpp"

#include <OpenNI.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include "drivers/openni2_replay/graspfill_replay_properties.hpp"

namespace graspfill::rt {
namespace {

// OpenNI2's extended error text comes with a leading tab and a trailing
// newline; keep it on one line.
std::string OpenNIError() {
  std::string text = openni::OpenNI::getExtendedError();
  for (char& c : text) {
    if (c == '\n' || c == '\t' || c == '\r') c = ' ';
  }
  const size_t first = text.find_first_not_of(' ');
  const size_t last = text.find_last_not_of(' ');
  if (first == std::string::npos) return "no details from OpenNI2";
  return text.substr(first, last - first + 1);
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Meters per unit of an OpenNI2 depth pixel format, 0 if not a depth format
// we read.
double MetersPerUnit(openni::PixelFormat format) {
  switch (format) {
    case openni::PIXEL_FORMAT_DEPTH_1_MM:
      return 0.001;
    case openni::PIXEL_FORMAT_DEPTH_100_UM:
      return 0.0001;
    default:
      return 0.0;
  }
}

std::string ModeText(const openni::VideoMode& m) {
  return std::to_string(m.getResolutionX()) + "x" + std::to_string(m.getResolutionY()) + "@" +
         std::to_string(m.getFps()) +
         (m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ? "/1mm" : "/100um");
}

int64_t WallClockMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

class OpenNI2Source::Impl {
 public:
  explicit Impl(const Config& config) : config_(config) {
    const std::string name = config_.uri.empty() ? std::string("any device") : "'" + config_.uri + "'";
    if (openni::OpenNI::initialize() != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: initialize failed: " + OpenNIError());
    }
    initialized_ = true;
    // From here on a throw must undo what is done: the destructor of a
    // half-built Impl does not run, so Close() runs by hand.
    try {
      Open(name);
    } catch (...) {
      Close();
      throw;
    }
  }

  ~Impl() { Close(); }

  FrameResult Next(DepthFrame* frame) {
    if (ended_) return FrameResult::kEndOfStream;
    if (recording_ && num_frames_ > 0 && frames_read_ >= num_frames_) {
      ended_ = true;
      return FrameResult::kEndOfStream;
    }
    if (replay_device_) {  // every frame served was read by an earlier call
      int frames_left = 1;
      if (device_.getProperty(openni2_replay::kDevicePropertyFramesLeft, &frames_left) == openni::STATUS_OK &&
          frames_left == 0) {
        ended_ = true;
        return FrameResult::kEndOfStream;
      }
    }
    openni::VideoStream* streams[] = {&stream_};
    int ready = -1;
    const openni::Status wait = openni::OpenNI::waitForAnyStream(streams, 1, &ready, config_.timeout_ms);
    if (wait == openni::STATUS_TIME_OUT) {
      if (recording_) {  // nothing more will come
        ended_ = true;
        return FrameResult::kEndOfStream;
      }
      return Bad("no depth frame within " + std::to_string(config_.timeout_ms) + " ms");
    }
    if (wait != openni::STATUS_OK) return Bad("wait failed: " + OpenNIError());
    if (stream_.readFrame(&frame_) != openni::STATUS_OK || !frame_.isValid()) {
      return Bad("readFrame failed: " + OpenNIError());
    }
    ++frames_read_;
    const int64_t received_utime = WallClockMicros();

    const double meters_per_unit = MetersPerUnit(frame_.getVideoMode().getPixelFormat());
    if (meters_per_unit == 0.0) return Bad("frame is not in a depth format");
    const int width = frame_.getWidth();
    const int height = frame_.getHeight();
    const int stride = frame_.getStrideInBytes();
    if (width <= 0 || height <= 0 || stride < 2 * width ||
        frame_.getDataSize() < stride * (height - 1) + 2 * width) {
      return Bad("frame has inconsistent size");
    }

    frame->utime =
        recording_ || replay_device_ ? static_cast<int64_t>(frame_.getTimestamp()) : received_utime;
    if (width != intrinsics_.width || height != intrinsics_.height) {
      return Bad("frame of " + std::to_string(width) + "x" + std::to_string(height) + " pixels in a " +
                 std::to_string(intrinsics_.width) + "x" + std::to_string(intrinsics_.height) + " mode");
    }
    frame->intrinsics = intrinsics_;
    frame->depth_m.resize(static_cast<size_t>(width) * height);
    const auto* bytes = static_cast<const uint8_t*>(frame_.getData());
    const std::vector<float>& meters = meters_per_unit == 0.001 ? meters_1mm_ : meters_100um_;
    // Rows may be padded (stride); pixels are host-endian uint16, copied
    // with memcpy since the buffer need not be aligned.
    for (int v = 0; v < height; ++v) {
      const uint8_t* src = bytes + static_cast<size_t>(v) * stride;
      float* dst = frame->depth_m.data() + static_cast<size_t>(v) * width;
      for (int u = 0; u < width; ++u) {
        uint16_t units;
        std::memcpy(&units, src + 2 * u, sizeof(units));
        dst[u] = meters[units];
      }
    }
    return FrameResult::kOk;
  }

  const std::string& last_error() const { return last_error_; }
  bool recording() const { return recording_; }
  bool paced_by_reader() const {
    return (recording_ && !config_.realtime_playback) || (replay_device_ && config_.replay_speed == 0.0f);
  }
  std::string mode_text() const { return ModeText(stream_.getVideoMode()); }

  void StartRecording(const std::string& path) {
    if (recorder_.create(path.c_str()) != openni::STATUS_OK ||
        recorder_.attach(stream_) != openni::STATUS_OK || recorder_.start() != openni::STATUS_OK) {
      recorder_.destroy();
      throw std::runtime_error("OpenNI2: cannot record into '" + path + "': " + OpenNIError());
    }
    // The recorder's own thread takes the start asynchronously and refuses
    // frames until then: give it time, so that the first frame is kept.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }

 private:
  void Open(const std::string& name) {
    recording_ = EndsWith(config_.uri, ".oni");
    const char* uri = config_.uri.empty() ? openni::ANY_DEVICE : config_.uri.c_str();
    if (device_.open(uri) != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: cannot open " + name + ": " + OpenNIError());
    }
    replay_device_ = device_.isPropertySupported(openni2_replay::kDevicePropertyFramesLeft);
    if (replay_device_ && device_.setProperty(openni2_replay::kDevicePropertySpeed, config_.replay_speed) !=
                              openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: " + name + " refuses the replay speed " +
                               std::to_string(config_.replay_speed));
    }
    if (!device_.hasSensor(openni::SENSOR_DEPTH)) {
      throw std::runtime_error("OpenNI2: " + name + " has no depth sensor");
    }
    if (stream_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: cannot create the depth stream of " + name + ": " + OpenNIError());
    }
    if (recording_) {
      openni::PlaybackControl* playback = device_.getPlaybackControl();
      if (playback != nullptr) {
        playback->setRepeatEnabled(false);
        // -1 = manual: a frame is produced per read, none is skipped.
        playback->setSpeed(config_.realtime_playback ? 1.0f : -1.0f);
        num_frames_ = playback->getNumberOfFrames(stream_);
      }
    } else {
      SetVideoMode(name);
      // Devices mirror by default (for user-facing apps); geometry needs
      // the true image. Not every driver supports the property.
      stream_.setMirroringEnabled(false);
    }
    if (stream_.start() != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: cannot start the depth stream of " + name + ": " + OpenNIError());
    }
    started_ = true;
    SetIntrinsics(name);
    // Meters per unit value, rounded once to float as depth_image_t's
    // decoding does, so that a replayed recording gives the same floats.
    meters_1mm_.resize(65536);
    meters_100um_.resize(65536);
    for (int u = 0; u < 65536; ++u) {
      meters_1mm_[u] = static_cast<float>(u * 0.001);
      meters_100um_[u] = static_cast<float>(u * 0.0001);
    }
  }

  // The stream's pinhole model, then Config::intrinsics.
  void SetIntrinsics(const std::string& name) {
    const openni::VideoMode mode = stream_.getVideoMode();
    CameraIntrinsics& K = intrinsics_;
    K.width = mode.getResolutionX();
    K.height = mode.getResolutionY();
    double exact[4];
    int size = sizeof(exact);
    if (stream_.isPropertySupported(openni2_replay::kStreamPropertyIntrinsics) &&
        stream_.getProperty(openni2_replay::kStreamPropertyIntrinsics, exact, &size) == openni::STATUS_OK &&
        size == sizeof(exact)) {
      K.fx = exact[0];
      K.fy = exact[1];
      K.cx = exact[2];
      K.cy = exact[3];
    } else {
      const float hfov = stream_.getHorizontalFieldOfView();
      const float vfov = stream_.getVerticalFieldOfView();
      const bool fov_given = config_.intrinsics.hfov_deg && config_.intrinsics.vfov_deg;
      if (!fov_given && !(hfov > 0.0f && hfov < 3.1f && vfov > 0.0f && vfov < 3.1f)) {
        throw std::runtime_error("OpenNI2: " + name + " reports no usable field of view (give --fov-deg)");
      }
      // Pinhole focal lengths from the field of view: tan(fov/2) = (w/2)/f.
      K.fx = 0.5 * K.width / std::tan(0.5 * hfov);
      K.fy = 0.5 * K.height / std::tan(0.5 * vfov);
      K.cx = 0.5 * (K.width - 1);
      K.cy = 0.5 * (K.height - 1);
    }
    const IntrinsicsOverride& o = config_.intrinsics;
    if (o.hfov_deg) K.fx = 0.5 * K.width / std::tan(0.5 * *o.hfov_deg * M_PI / 180.0);
    if (o.vfov_deg) K.fy = 0.5 * K.height / std::tan(0.5 * *o.vfov_deg * M_PI / 180.0);
    if (o.fx) K.fx = *o.fx;
    if (o.fy) K.fy = *o.fy;
    if (o.cx) K.cx = *o.cx;
    if (o.cy) K.cy = *o.cy;
  }

  bool Fits(const openni::VideoMode& m, openni::PixelFormat format) const {
    return m.getPixelFormat() == format && (config_.width == 0 || m.getResolutionX() == config_.width) &&
           (config_.height == 0 || m.getResolutionY() == config_.height) &&
           (config_.fps == 0 || m.getFps() == config_.fps);
  }

  void SetVideoMode(const std::string& name) {
    const openni::PixelFormat wanted = config_.depth_mode == DepthMode::k100um
                                           ? openni::PIXEL_FORMAT_DEPTH_100_UM
                                           : openni::PIXEL_FORMAT_DEPTH_1_MM;
    if (Fits(stream_.getVideoMode(), wanted)) return;  // the device's own
    const openni::SensorInfo& info = stream_.getSensorInfo();
    const openni::Array<openni::VideoMode>& modes = info.getSupportedVideoModes();
    std::string available;
    for (int i = 0; i < modes.getSize(); ++i) {
      const openni::VideoMode& m = modes[i];
      if (Fits(m, wanted)) {
        if (stream_.setVideoMode(m) != openni::STATUS_OK) {
          throw std::runtime_error("OpenNI2: cannot set the video mode of " + name + ": " + OpenNIError());
        }
        return;
      }
      if (MetersPerUnit(m.getPixelFormat()) != 0.0) available += " " + ModeText(m);
    }
    auto field = [](int v) { return v == 0 ? std::string("*") : std::to_string(v); };
    throw std::runtime_error("OpenNI2: " + name + " has no depth mode " + field(config_.width) + "x" +
                             field(config_.height) + "@" + field(config_.fps) +
                             (wanted == openni::PIXEL_FORMAT_DEPTH_1_MM ? "/1mm" : "/100um") +
                             "; available:" + (available.empty() ? " none" : available));
  }

  void Close() {
    if (recorder_.isValid()) {
      recorder_.stop();
      recorder_.destroy();  // writes what is queued, then the seek table
    }
    frame_.release();
    if (started_) stream_.stop();
    // OpenNI2's file player (libOniFile) walks its stream list without its
    // lock, and past the end of a file it does so in a busy loop: a stream
    // destroyed under it crashed that thread (1 in ~16 `live --device
    // FILE.oni` runs under load). Stopped, its stream sends the loop to
    // 10 ms sleeps; this waits for it to get there.
    if (started_ && recording_) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    started_ = false;
    stream_.destroy();
    device_.close();
    if (initialized_) openni::OpenNI::shutdown();
    initialized_ = false;
  }

  FrameResult Bad(const std::string& why) {
    last_error_ = "OpenNI2: " + why;
    return FrameResult::kBadFrame;
  }

  Config config_;
  bool initialized_{false};
  bool started_{false};
  bool recording_{false};
  bool ended_{false};
  int num_frames_{0};
  int frames_read_{0};
  bool replay_device_{false};
  CameraIntrinsics intrinsics_;
  std::vector<float> meters_1mm_, meters_100um_;  // by unit value
  openni::Device device_;
  openni::VideoStream stream_;
  openni::VideoFrameRef frame_;
  openni::Recorder recorder_;
  std::string last_error_;
};

OpenNI2Source::OpenNI2Source(const Config& config) : impl_(std::make_unique<Impl>(config)) {}

OpenNI2Source::~OpenNI2Source() = default;

FrameResult OpenNI2Source::Next(DepthFrame* frame) { return impl_->Next(frame); }

FrameResult OpenNI2Source::Next(SourceEvent* event) {
  event->kind = SourceEvent::Kind::kDepth;
  const FrameResult result = impl_->Next(&event->depth);
  if (result == FrameResult::kBadFrame) event->error = impl_->last_error();
  return result;
}

const std::string& OpenNI2Source::last_error() const { return impl_->last_error(); }

bool OpenNI2Source::is_recording() const { return impl_->recording(); }

bool OpenNI2Source::paced_by_reader() const { return impl_->paced_by_reader(); }

std::string OpenNI2Source::mode_text() const { return impl_->mode_text(); }

void OpenNI2Source::StartRecording(const std::string& oni_path) { impl_->StartRecording(oni_path); }

}  // namespace graspfill::rt
