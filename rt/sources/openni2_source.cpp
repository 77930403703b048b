#include "sources/openni2_source.hpp"

#include <OpenNI.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

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
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
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

int64_t WallClockMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

class OpenNI2Source::Impl {
 public:
  explicit Impl(const Config& config) : config_(config) {
    const std::string name =
        config_.uri.empty() ? std::string("any device") : "'" + config_.uri + "'";
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
    openni::VideoStream* streams[] = {&stream_};
    int ready = -1;
    const openni::Status wait = openni::OpenNI::waitForAnyStream(
        streams, 1, &ready, config_.timeout_ms);
    if (wait == openni::STATUS_TIME_OUT) {
      if (recording_) {  // nothing more will come
        ended_ = true;
        return FrameResult::kEndOfStream;
      }
      return Bad("no depth frame within " +
                 std::to_string(config_.timeout_ms) + " ms");
    }
    if (wait != openni::STATUS_OK) return Bad("wait failed: " + OpenNIError());
    if (stream_.readFrame(&frame_) != openni::STATUS_OK || !frame_.isValid()) {
      return Bad("readFrame failed: " + OpenNIError());
    }
    ++frames_read_;
    const int64_t received_utime = WallClockMicros();

    const double meters_per_unit =
        MetersPerUnit(frame_.getVideoMode().getPixelFormat());
    if (meters_per_unit == 0.0) return Bad("frame is not in a depth format");
    const int width = frame_.getWidth();
    const int height = frame_.getHeight();
    const int stride = frame_.getStrideInBytes();
    if (width <= 0 || height <= 0 || stride < 2 * width ||
        frame_.getDataSize() < stride * (height - 1) + 2 * width) {
      return Bad("frame has inconsistent size");
    }

    frame->utime = recording_ ? static_cast<int64_t>(frame_.getTimestamp())
                              : received_utime;
    CameraIntrinsics& K = frame->intrinsics;
    K.width = width;
    K.height = height;
    // Pinhole focal lengths from the field of view: tan(fov/2) = (w/2)/f.
    K.fx = 0.5 * width / std::tan(0.5 * horizontal_fov_rad_);
    K.fy = 0.5 * height / std::tan(0.5 * vertical_fov_rad_);
    K.cx = 0.5 * (width - 1);
    K.cy = 0.5 * (height - 1);
    frame->depth_m.resize(static_cast<size_t>(width) * height);
    const auto* bytes = static_cast<const uint8_t*>(frame_.getData());
    const float scale = static_cast<float>(meters_per_unit);
    // Rows may be padded (stride); pixels are host-endian uint16, copied
    // with memcpy since the buffer need not be aligned.
    for (int v = 0; v < height; ++v) {
      const uint8_t* src = bytes + static_cast<size_t>(v) * stride;
      float* dst = frame->depth_m.data() + static_cast<size_t>(v) * width;
      for (int u = 0; u < width; ++u) {
        uint16_t units;
        std::memcpy(&units, src + 2 * u, sizeof(units));
        dst[u] = static_cast<float>(units) * scale;
      }
    }
    return FrameResult::kOk;
  }

  const std::string& last_error() const { return last_error_; }
  bool recording() const { return recording_; }

 private:
  void Open(const std::string& name) {
    recording_ = EndsWith(config_.uri, ".oni");
    const char* uri =
        config_.uri.empty() ? openni::ANY_DEVICE : config_.uri.c_str();
    if (device_.open(uri) != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: cannot open " + name + ": " +
                               OpenNIError());
    }
    if (!device_.hasSensor(openni::SENSOR_DEPTH)) {
      throw std::runtime_error("OpenNI2: " + name + " has no depth sensor");
    }
    if (stream_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
      throw std::runtime_error("OpenNI2: cannot create the depth stream of " +
                               name + ": " + OpenNIError());
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
      throw std::runtime_error("OpenNI2: cannot start the depth stream of " +
                               name + ": " + OpenNIError());
    }
    started_ = true;
    horizontal_fov_rad_ = stream_.getHorizontalFieldOfView();
    vertical_fov_rad_ = stream_.getVerticalFieldOfView();
    if (!(horizontal_fov_rad_ > 0.0f && horizontal_fov_rad_ < 3.1f &&
          vertical_fov_rad_ > 0.0f && vertical_fov_rad_ < 3.1f)) {
      throw std::runtime_error("OpenNI2: " + name +
                               " reports no usable field of view");
    }
  }

  void SetVideoMode(const std::string& name) {
    const openni::PixelFormat wanted =
        config_.depth_mode == DepthMode::k100um
            ? openni::PIXEL_FORMAT_DEPTH_100_UM
            : openni::PIXEL_FORMAT_DEPTH_1_MM;
    const openni::SensorInfo& info = stream_.getSensorInfo();
    const openni::Array<openni::VideoMode>& modes =
        info.getSupportedVideoModes();
    std::string available;
    for (int i = 0; i < modes.getSize(); ++i) {
      const openni::VideoMode& m = modes[i];
      if (m.getPixelFormat() == wanted && m.getResolutionX() == config_.width &&
          m.getResolutionY() == config_.height && m.getFps() == config_.fps) {
        if (stream_.setVideoMode(m) != openni::STATUS_OK) {
          throw std::runtime_error("OpenNI2: cannot set the video mode of " +
                                   name + ": " + OpenNIError());
        }
        return;
      }
      if (MetersPerUnit(m.getPixelFormat()) != 0.0) {
        available += " " + std::to_string(m.getResolutionX()) + "x" +
                     std::to_string(m.getResolutionY()) + "@" +
                     std::to_string(m.getFps()) +
                     (m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM
                          ? "/1mm"
                          : "/100um");
      }
    }
    throw std::runtime_error(
        "OpenNI2: " + name + " has no depth mode " +
        std::to_string(config_.width) + "x" + std::to_string(config_.height) +
        "@" + std::to_string(config_.fps) +
        (wanted == openni::PIXEL_FORMAT_DEPTH_1_MM ? "/1mm" : "/100um") +
        "; available:" + (available.empty() ? " none" : available));
  }

  void Close() {
    frame_.release();
    if (started_) stream_.stop();
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
  float horizontal_fov_rad_{0.0f};
  float vertical_fov_rad_{0.0f};
  openni::Device device_;
  openni::VideoStream stream_;
  openni::VideoFrameRef frame_;
  std::string last_error_;
};

OpenNI2Source::OpenNI2Source(const Config& config)
    : impl_(std::make_unique<Impl>(config)) {}

OpenNI2Source::~OpenNI2Source() = default;

FrameResult OpenNI2Source::Next(DepthFrame* frame) { return impl_->Next(frame); }

FrameResult OpenNI2Source::Next(SourceEvent* event) {
  event->kind = SourceEvent::Kind::kDepth;
  const FrameResult result = impl_->Next(&event->depth);
  if (result == FrameResult::kBadFrame) event->error = impl_->last_error();
  return result;
}

const std::string& OpenNI2Source::last_error() const {
  return impl_->last_error();
}

bool OpenNI2Source::is_recording() const { return impl_->recording(); }

}  // namespace graspfill::rt
