// SPDX-License-Identifier: BSD-3-Clause
// libGraspfillReplay: an OpenNI2 driver (OniDriverAPI) whose one kind of
// device is a graspfill recording. `openni::Device::open("graspfill-replay:
// PATH.lcmlog")` gives a device with a depth sensor that serves the log's
// depth images, in order, with their recorded timestamps [us], in 1 mm or
// 100 um units, at the recorded resolution or decimated by two; the field
// of view (and, through kStreamPropertyIntrinsics, the exact pinhole) comes
// from the recorded intrinsics.
//
// Frames are made on demand: OpenNI2 pokes a device (tryManualTrigger)
// whenever a reader waits for a frame and none is waiting, and only then
// does this driver decode the next one. OpenNI2 keeps only a stream's newest
// frame, so a device that pushed frames at its own pace would lose them
// under a slow reader; this one never does. At speed 1 a frame also waits
// for its recorded time (after the first), as a camera would; at speed 0
// it goes out at once. A reader that only registers a frame listener and
// never waits gets no frame.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <list>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

// OniDriverAPI.h's export macros allocate through XnLib's XN_NEW/XN_DELETE,
// which a driver built outside OpenNI2's tree has to supply.
#define XN_NEW(type, ...) new (std::nothrow) type(__VA_ARGS__)
#define XN_DELETE(p) delete (p)
#include <Driver/OniDriverAPI.h>

#include "graspfill/io/messages.hpp"
#include "graspfill_replay_properties.hpp"
#include "replay_recording.hpp"

namespace graspfill::openni2_replay {
namespace {

// The largest depth value served: OpenNI2's recorder sizes its 16z codec's
// table by the stream's MAX_VALUE and indexes it with every pixel, so no
// pixel may exceed it (nor be 65535); larger depths become 0 (no return).
constexpr int kMaxDepthUnits = 65534;

template <typename T>
OniStatus Put(const T& value, void* data, int* size) {
  if (data == nullptr || size == nullptr || *size < static_cast<int>(sizeof(T))) {
    return ONI_STATUS_BAD_PARAMETER;
  }
  std::memcpy(data, &value, sizeof(T));
  *size = sizeof(T);
  return ONI_STATUS_OK;
}

template <typename T>
bool Take(const void* data, int size, T* value) {
  if (data == nullptr || size != static_cast<int>(sizeof(T))) return false;
  std::memcpy(value, data, sizeof(T));
  return true;
}

double MetersPerUnit(OniPixelFormat format) {
  return format == ONI_PIXEL_FORMAT_DEPTH_100_UM ? 0.0001 : 0.001;
}

// Video modes of a recording: its own size, then half of it (every second
// pixel of every second row) where the size is even; its own units first.
std::vector<OniVideoMode> ModesOf(const RecordingIndex& index) {
  const OniPixelFormat own =
      index.depth_scale_m < 0.00095 ? ONI_PIXEL_FORMAT_DEPTH_100_UM : ONI_PIXEL_FORMAT_DEPTH_1_MM;
  const OniPixelFormat other =
      own == ONI_PIXEL_FORMAT_DEPTH_1_MM ? ONI_PIXEL_FORMAT_DEPTH_100_UM : ONI_PIXEL_FORMAT_DEPTH_1_MM;
  const int w = index.intrinsics.width, h = index.intrinsics.height;
  std::vector<OniVideoMode> modes;
  for (int decimation : {1, 2}) {
    if (decimation == 2 && (w % 2 != 0 || h % 2 != 0)) continue;
    for (OniPixelFormat format : {own, other}) {
      modes.push_back({format, w / decimation, h / decimation, index.fps});
    }
  }
  return modes;
}

class ReplayStream : public oni::driver::StreamBase {
 public:
  explicit ReplayStream(const RecordingIndex& index)
      : index_(index), modes_(ModesOf(index)), mode_(modes_.front()) {}

  OniStatus start() override {
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      reader_ = std::make_unique<RecordingReader>(index_);  // from the start
    } catch (const std::exception&) {
      return ONI_STATUS_ERROR;
    }
    frames_left_ = index_.num_frames;
    frame_index_ = 0;
    started_ = true;
    return ONI_STATUS_OK;
  }
  void stop() override {
    std::lock_guard<std::mutex> lock(mutex_);
    started_ = false;
    reader_.reset();
  }

  OniStatus getProperty(int id, void* data, int* size) override {
    std::lock_guard<std::mutex> lock(mutex_);
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE:
        return Put(mode_, data, size);
      case ONI_STREAM_PROPERTY_CROPPING: {
        OniCropping none{};            // cropping is not supported, but answered:
        return Put(none, data, size);  // .oni playback needs it recorded
      }
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
        return Put(static_cast<float>(2.0 * std::atan(0.5 * mode_.resolutionX / Fx())), data, size);
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
        return Put(static_cast<float>(2.0 * std::atan(0.5 * mode_.resolutionY / Fy())), data, size);
      case ONI_STREAM_PROPERTY_MAX_VALUE:
        return Put(int{kMaxDepthUnits}, data, size);
      case ONI_STREAM_PROPERTY_MIN_VALUE:
        return Put(int{0}, data, size);
      case ONI_STREAM_PROPERTY_STRIDE:
        return Put(int{2 * mode_.resolutionX}, data, size);
      case ONI_STREAM_PROPERTY_MIRRORING:
        return Put(OniBool{FALSE}, data, size);
      case kStreamPropertyIntrinsics: {
        const double s = Scale();
        const CameraIntrinsics& K = index_.intrinsics;
        if (data == nullptr || size == nullptr || *size < static_cast<int>(4 * sizeof(double))) {
          return ONI_STATUS_BAD_PARAMETER;
        }
        const double values[4] = {K.fx * s, K.fy * s, K.cx * s, K.cy * s};
        std::memcpy(data, values, sizeof(values));
        *size = sizeof(values);
        return ONI_STATUS_OK;
      }
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  OniStatus setProperty(int id, const void* data, int size) override {
    std::lock_guard<std::mutex> lock(mutex_);
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE: {
        OniVideoMode wanted;
        if (!Take(data, size, &wanted)) return ONI_STATUS_BAD_PARAMETER;
        if (started_) return ONI_STATUS_OUT_OF_FLOW;
        for (const OniVideoMode& m : modes_) {
          if (m.pixelFormat == wanted.pixelFormat && m.resolutionX == wanted.resolutionX &&
              m.resolutionY == wanted.resolutionY && m.fps == wanted.fps) {
            mode_ = m;
            return ONI_STATUS_OK;
          }
        }
        return ONI_STATUS_NOT_SUPPORTED;
      }
      case ONI_STREAM_PROPERTY_CROPPING: {
        OniCropping cropping;
        if (!Take(data, size, &cropping)) return ONI_STATUS_BAD_PARAMETER;
        return cropping.enabled ? ONI_STATUS_NOT_SUPPORTED : ONI_STATUS_OK;
      }
      case ONI_STREAM_PROPERTY_MIRRORING: {
        OniBool mirror;
        if (!Take(data, size, &mirror)) return ONI_STATUS_BAD_PARAMETER;
        return mirror ? ONI_STATUS_NOT_SUPPORTED : ONI_STATUS_OK;
      }
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  OniBool isPropertySupported(int id) override {
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE:
      case ONI_STREAM_PROPERTY_CROPPING:
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
      case ONI_STREAM_PROPERTY_MAX_VALUE:
      case ONI_STREAM_PROPERTY_MIN_VALUE:
      case ONI_STREAM_PROPERTY_STRIDE:
      case ONI_STREAM_PROPERTY_MIRRORING:
      case kStreamPropertyIntrinsics:
        return TRUE;
      default:
        return FALSE;
    }
  }

  const std::vector<OniVideoMode>& modes() const { return modes_; }

  int frames_left() {
    std::lock_guard<std::mutex> lock(mutex_);
    return started_ ? frames_left_ : index_.num_frames;
  }

  // The reader waits for a frame and has none: make the next one (see the
  // file comment). `speed` as kDevicePropertySpeed.
  void ServeNext(float speed) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!started_ || frames_left_ <= 0) return;
    if (!reader_->Next(&decoded_)) {  // fewer good frames than indexed
      frames_left_ = 0;
      return;
    }
    --frames_left_;
    if (speed > 0.0f) {
      const auto now = std::chrono::steady_clock::now();
      if (frame_index_ == 0) first_served_ = now;
      const auto due =
          first_served_ +
          std::chrono::microseconds(static_cast<int64_t>((decoded_.utime - index_.first_utime) / speed));
      lock.unlock();
      if (due > now) std::this_thread::sleep_until(due);
      lock.lock();
      if (!started_) return;
    }
    OniFrame* frame = getServices().acquireFrame();
    if (frame == nullptr) return;
    Fill(frame);
    lock.unlock();
    raiseNewFrame(frame);
    getServices().releaseFrame(frame);
  }

 private:
  int Decimation() const { return index_.intrinsics.width / mode_.resolutionX; }
  double Scale() const { return 1.0 / Decimation(); }
  double Fx() const { return index_.intrinsics.fx * Scale(); }
  double Fy() const { return index_.intrinsics.fy * Scale(); }

  // The decoded frame, in the mode's units and size, into OpenNI2's buffer.
  void Fill(OniFrame* frame) {
    const int w = mode_.resolutionX, h = mode_.resolutionY, step = Decimation();
    const double units_per_m = 1.0 / MetersPerUnit(mode_.pixelFormat);
    auto* out = static_cast<uint16_t*>(frame->data);
    const int src_w = index_.intrinsics.width;
    for (int v = 0; v < h; ++v) {
      const float* row = decoded_.depth_m.data() + static_cast<size_t>(v) * step * src_w;
      for (int u = 0; u < w; ++u) {
        const double units = std::round(static_cast<double>(row[u * step]) * units_per_m);
        out[static_cast<size_t>(v) * w + u] =
            units > 0.0 && units <= kMaxDepthUnits ? static_cast<uint16_t>(units) : 0;
      }
    }
    frame->dataSize = 2 * w * h;
    frame->sensorType = ONI_SENSOR_DEPTH;
    frame->timestamp = static_cast<uint64_t>(decoded_.utime);
    frame->frameIndex = ++frame_index_;
    frame->width = w;
    frame->height = h;
    frame->videoMode = mode_;
    frame->croppingEnabled = FALSE;
    frame->cropOriginX = 0;
    frame->cropOriginY = 0;
    frame->stride = 2 * w;
  }

  const RecordingIndex index_;
  const std::vector<OniVideoMode> modes_;
  std::mutex mutex_;
  OniVideoMode mode_;
  bool started_{false};
  std::unique_ptr<RecordingReader> reader_;
  DepthFrame decoded_;
  int frames_left_{0};
  int frame_index_{0};
  std::chrono::steady_clock::time_point first_served_;
};

class ReplayDevice : public oni::driver::DeviceBase {
 public:
  explicit ReplayDevice(const RecordingIndex& index) : index_(index) {
    const std::vector<OniVideoMode> modes = ModesOf(index);
    modes_.assign(modes.begin(), modes.end());
    sensor_.sensorType = ONI_SENSOR_DEPTH;
    sensor_.numSupportedVideoModes = static_cast<int>(modes_.size());
    sensor_.pSupportedVideoModes = modes_.data();
  }

  OniStatus getSensorInfoList(OniSensorInfo** sensors, int* count) override {
    *sensors = &sensor_;
    *count = 1;
    return ONI_STATUS_OK;
  }

  oni::driver::StreamBase* createStream(OniSensorType type) override {
    if (type != ONI_SENSOR_DEPTH || stream_ != nullptr) return nullptr;
    stream_ = new (std::nothrow) ReplayStream(index_);
    return stream_;
  }
  void destroyStream(oni::driver::StreamBase* stream) override {
    if (stream == stream_) stream_ = nullptr;
    delete stream;
  }

  OniStatus getProperty(int id, void* data, int* size) override {
    switch (id) {
      case kDevicePropertySpeed:
        return Put(speed_, data, size);
      case kDevicePropertyFramesLeft:
        return Put(stream_ != nullptr ? stream_->frames_left() : index_.num_frames, data, size);
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }
  OniStatus setProperty(int id, const void* data, int size) override {
    if (id != kDevicePropertySpeed) return ONI_STATUS_NOT_SUPPORTED;
    float speed;
    if (!Take(data, size, &speed) || !(speed >= 0.0f) || !std::isfinite(speed)) {
      return ONI_STATUS_BAD_PARAMETER;
    }
    speed_ = speed;
    return ONI_STATUS_OK;
  }
  OniBool isPropertySupported(int id) override {
    return id == kDevicePropertySpeed || id == kDevicePropertyFramesLeft;
  }

  OniStatus tryManualTrigger() override {
    if (stream_ != nullptr) stream_->ServeNext(speed_);
    return ONI_STATUS_OK;
  }

 private:
  const RecordingIndex index_;
  std::vector<OniVideoMode> modes_;
  OniSensorInfo sensor_{};
  ReplayStream* stream_{nullptr};
  float speed_{1.0f};
};

class ReplayDriver : public oni::driver::DriverBase {
 public:
  explicit ReplayDriver(OniDriverServices* services) : DriverBase(services) {}

  // No device is plugged in: a replay device appears when asked for by URI.
  OniStatus tryDevice(const char* uri) override {
    const std::string text = uri != nullptr ? uri : "";
    const std::string prefix = kUriPrefix;
    if (text.compare(0, prefix.size(), prefix) != 0) return ONI_STATUS_ERROR;
    Known* known = Find(text);
    if (known == nullptr) {
      try {
        known = &known_.emplace_back(
            Known{IndexRecording(text.substr(prefix.size()), io::ChannelNames().depth), {}});
      } catch (const std::exception& e) {
        getServices().errorLoggerAppend("graspfill-replay: %s", e.what());
        return ONI_STATUS_ERROR;
      }
      OniDeviceInfo& info = known->info;
      std::snprintf(info.uri, sizeof(info.uri), "%s", text.c_str());
      std::snprintf(info.vendor, sizeof(info.vendor), "graspfill");
      std::snprintf(info.name, sizeof(info.name), "graspfill replay");
    }
    deviceConnected(&known->info);
    return ONI_STATUS_OK;
  }

  oni::driver::DeviceBase* deviceOpen(const char* uri, const char* /*mode*/) override {
    Known* known = Find(uri != nullptr ? uri : "");
    if (known == nullptr) return nullptr;
    return new (std::nothrow) ReplayDevice(known->index);
  }
  void deviceClose(oni::driver::DeviceBase* device) override { delete device; }
  void shutdown() override { known_.clear(); }

 private:
  struct Known {
    RecordingIndex index;
    OniDeviceInfo info;
  };
  Known* Find(const std::string& uri) {
    for (Known& k : known_) {
      if (uri == k.info.uri) return &k;
    }
    return nullptr;
  }
  std::list<Known> known_;  // stable addresses: OpenNI2 keeps &info
};

}  // namespace
}  // namespace graspfill::openni2_replay

ONI_EXPORT_DRIVER(graspfill::openni2_replay::ReplayDriver)
