// SPDX-License-Identifier: BSD-3-Clause
// Message conversion. Two rules shape this file:
//  - Bytes from the bus are untrusted. The lcm-gen decoders resize their
//    vectors to the count read from the wire *before* checking that the
//    bytes are there (a negative or huge count throws or allocates
//    gigabytes), so every message is first walked with WireReader, which
//    checks each count against the bytes left, and only then decoded.
//  - Depth images arrive at 30 Hz: they are parsed in place (no copy of the
//    payload) and inflated with a per-thread zlib stream into per-thread
//    scratch, so the steady state allocates nothing.
#include "graspfill/io/messages.hpp"

#include "packed_points.hpp"

#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <graspfill/depth_image_t.hpp>
#include <graspfill/gripper_state_t.hpp>
#include <graspfill/gripper_state_v1_t.hpp>
#include <graspfill/hole_t.hpp>
#include <graspfill/module_status_t.hpp>
#include <graspfill/object_cloud_t.hpp>
#include <graspfill/session_description_t.hpp>
#include <graspfill/version.hpp>

namespace graspfill::io {
namespace {

// Tolerance on |q| before a quaternion counts as not a rotation.
constexpr double kUnitQuaternionTolerance = 1e-3;

// Why the decode in progress on this thread failed; read by the public
// Decode* wrappers at the end of the file.
thread_local MessageError t_reason = MessageError::kNone;

void SetError(std::string* error, const std::string& message,
              MessageError reason = MessageError::kMalformed) {
  t_reason = reason;
  if (error != nullptr) *error = message;
}

std::string FormatLimit(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// `text` fit for a one-line message: bytes outside printable ASCII as \xHH,
// at most `max_chars` of it.
std::string Printable(const std::string& text, size_t max_chars) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < max_chars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

bool UtimeInRange(const char* type, int64_t utime, std::string* error) {
  if (utime < 0 || utime > kMaxUtime) {
    SetError(error, std::string(type) + ": utime " + std::to_string(utime) + " outside 0.." +
                        std::to_string(kMaxUtime) + " us",
             MessageError::kBadTimestamp);
    return false;
  }
  return true;
}

// Reads LCM's wire format (big-endian, counts before arrays) with bounds
// checks. Every accessor returns false instead of reading past the end.
class WireReader {
 public:
  WireReader(const void* data, size_t size)
      : data_(static_cast<const uint8_t*>(data)), size_(size) {}

  size_t remaining() const { return size_ - pos_; }

  bool Skip(size_t n) {
    if (n > remaining()) return false;
    pos_ += n;
    return true;
  }
  bool Bytes(size_t n, const uint8_t** p) {
    if (n > remaining()) return false;
    *p = data_ + pos_;
    pos_ += n;
    return true;
  }
  bool I8(int8_t* v) {
    uint64_t u;
    if (!BigEndian(1, &u)) return false;
    *v = static_cast<int8_t>(u);
    return true;
  }
  bool I32(int32_t* v) {
    uint64_t u;
    if (!BigEndian(4, &u)) return false;
    *v = static_cast<int32_t>(static_cast<uint32_t>(u));
    return true;
  }
  bool I64(int64_t* v) {
    uint64_t u;
    if (!BigEndian(8, &u)) return false;
    *v = static_cast<int64_t>(u);
    return true;
  }
  bool F64(double* v) {
    uint64_t u;
    if (!BigEndian(8, &u)) return false;
    std::memcpy(v, &u, sizeof(*v));
    return true;
  }
  // An array count followed by `count` elements of `element_bytes` each:
  // the count must be >= 0 and the elements must fit in what is left.
  bool Count(int32_t* count, size_t element_bytes) {
    return I32(count) && CountFits(*count, element_bytes);
  }
  bool CountFits(int32_t count, size_t element_bytes) const {
    return count >= 0 && static_cast<size_t>(count) <=
                             remaining() / (element_bytes ? element_bytes : 1);
  }
  // An LCM string: int32 length including the NUL, then the bytes. The
  // NUL must end it and be its only one: lcm-gen decodes embedded NULs
  // into std::string but encodes with strlen, so such a string would
  // decode and then fail to re-encode (found by fuzz_object_cloud).
  bool SkipString() {
    int32_t length;
    const uint8_t* bytes = nullptr;
    if (!I32(&length) || length < 1 || !Bytes(static_cast<size_t>(length), &bytes)) return false;
    return std::memchr(bytes, 0, static_cast<size_t>(length)) == bytes + length - 1;
  }
  bool Hash(int64_t expected) {
    int64_t hash;
    return I64(&hash) && hash == expected;
  }

 private:
  bool BigEndian(size_t n, uint64_t* v) {
    if (n > remaining()) return false;
    uint64_t u = 0;
    for (size_t i = 0; i < n; ++i) u = (u << 8) | data_[pos_ + i];
    pos_ += n;
    *v = u;
    return true;
  }

  const uint8_t* data_;
  size_t size_;
  size_t pos_{0};
};

bool AllFinite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// Builds an isometry from position + (w, x, y, z) after checking both.
bool PoseFromWire(const char* type, const double position[3],
                  const double orientation[4], Eigen::Isometry3d* T,
                  std::string* error) {
  if (!AllFinite(position, 3) || !AllFinite(orientation, 4)) {
    SetError(error, std::string(type) + ": pose is not finite", MessageError::kBadPose);
    return false;
  }
  Eigen::Quaterniond q(orientation[0], orientation[1], orientation[2],
                       orientation[3]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    SetError(error, std::string(type) +
                        ": orientation is not a unit quaternion (|q| = " +
                        std::to_string(norm) + ")",
             MessageError::kBadPose);
    return false;
  }
  q.normalize();
  T->setIdentity();
  T->linear() = q.toRotationMatrix();
  T->translation() = Eigen::Vector3d(position[0], position[1], position[2]);
  return true;
}

void PoseToWire(const Eigen::Isometry3d& T, double position[3],
                double orientation[4]) {
  Eigen::Quaterniond q(T.rotation());
  q.normalize();
  for (int i = 0; i < 3; ++i) position[i] = T.translation()[i];
  orientation[0] = q.w();
  orientation[1] = q.x();
  orientation[2] = q.y();
  orientation[3] = q.z();
}

template <typename Message>
std::vector<uint8_t> EncodeMessage(const Message& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  const int n = msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (n != static_cast<int>(bytes.size())) {
    throw std::logic_error(std::string("lcm encode failed for ") +
                           Message::getTypeName());
  }
  return bytes;
}

// Runs the lcm-gen decoder on bytes that a walker has already validated.
// The try/catch is a second line of defence (bad_alloc) since handlers on
// the bus must not throw.
template <typename Message>
bool DecodeMessage(const void* data, size_t size, Message* msg,
                   std::string* error) {
  try {
    const int n = msg->decode(data, 0, static_cast<int>(size));
    if (n != static_cast<int>(size)) {
      SetError(error, std::string(Message::getTypeName()) +
                          ": lcm decode failed");
      return false;
    }
  } catch (const std::exception& e) {
    SetError(error, std::string(Message::getTypeName()) +
                        ": lcm decode failed: " + e.what());
    return false;
  }
  return true;
}

// Common checks before any walk: a null pointer or a message bigger than
// lcm's int-sized decoders can address.
bool CheckBuffer(const void* data, size_t size, const void* out,
                 const char* type, std::string* error) {
  if (out == nullptr) {
    SetError(error, std::string(type) + ": null output");
    return false;
  }
  if (data == nullptr && size != 0) {
    SetError(error, std::string(type) + ": null data");
    return false;
  }
  if (size > static_cast<size_t>(INT_MAX)) {
    SetError(error, std::string(type) + ": message too large");
    return false;
  }
  return true;
}

// ---- Depth -----------------------------------------------------------------

// Per-thread zlib streams: inflateInit/deflateInit allocate tens to hundreds
// of kilobytes each, so each thread pays that once, not per frame.
struct ZlibScratch {
  z_stream inflater{};
  bool inflater_ready{false};
  z_stream deflater{};
  bool deflater_ready{false};
  std::vector<uint8_t> raw;  // delta-coded little-endian samples

  ~ZlibScratch() {
    if (inflater_ready) inflateEnd(&inflater);
    if (deflater_ready) deflateEnd(&deflater);
  }
};

ZlibScratch& Scratch() {
  thread_local ZlibScratch scratch;
  return scratch;
}

// Inflates exactly `out_size` bytes from a complete zlib stream; never
// writes past `out_size` (a stream that would inflate to more, a zlib bomb,
// stops there and is refused).
bool Inflate(const uint8_t* in, size_t in_size, uint8_t* out, size_t out_size,
             std::string* error) {
  ZlibScratch& s = Scratch();
  if (!s.inflater_ready) {
    if (inflateInit(&s.inflater) != Z_OK) {
      SetError(error, "depth_image_t: zlib init failed");
      return false;
    }
    s.inflater_ready = true;
  } else {
    inflateReset(&s.inflater);
  }
  z_stream& zs = s.inflater;
  zs.next_in = const_cast<Bytef*>(in);
  zs.avail_in = static_cast<uInt>(in_size);
  zs.next_out = out;
  zs.avail_out = static_cast<uInt>(out_size);
  const int rc = inflate(&zs, Z_FINISH);
  if (rc != Z_STREAM_END) {
    SetError(error, std::string("depth_image_t: corrupt zlib data (") +
                        (zs.msg ? zs.msg : "size mismatch") + ")");
    return false;
  }
  if (zs.avail_out != 0 || zs.avail_in != 0) {
    SetError(error, "depth_image_t: zlib data does not match the image size");
    return false;
  }
  return true;
}

std::vector<uint8_t> Deflate(const std::vector<uint8_t>& raw) {
  ZlibScratch& s = Scratch();
  if (!s.deflater_ready) {
    // Z_BEST_SPEED: ~6 ms for a 640x480 frame on one core; level 6 gains
    // ~15% more but costs ~50 ms, too slow for 30 Hz.
    if (deflateInit(&s.deflater, Z_BEST_SPEED) != Z_OK) {
      throw std::runtime_error("EncodeDepthImage: zlib init failed");
    }
    s.deflater_ready = true;
  } else {
    deflateReset(&s.deflater);
  }
  z_stream& zs = s.deflater;
  std::vector<uint8_t> out(deflateBound(&zs, static_cast<uLong>(raw.size())));
  zs.next_in = const_cast<Bytef*>(raw.data());
  zs.avail_in = static_cast<uInt>(raw.size());
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  if (deflate(&zs, Z_FINISH) != Z_STREAM_END) {
    throw std::runtime_error("EncodeDepthImage: zlib deflate failed");
  }
  out.resize(zs.total_out);
  return out;
}

}  // namespace

std::vector<uint8_t> EncodeDepthImage(const DepthFrame& frame,
                                      DepthEncoding encoding,
                                      double depth_scale_m) {
  const CameraIntrinsics& K = frame.intrinsics;
  if (K.width <= 0 || K.height <= 0 ||
      int64_t{K.width} * K.height > kMaxDepthPixels) {
    throw std::invalid_argument("EncodeDepthImage: bad image size " +
                                std::to_string(K.width) + "x" +
                                std::to_string(K.height));
  }
  const size_t num_pixels = static_cast<size_t>(K.width) * K.height;
  if (frame.depth_m.size() != num_pixels) {
    throw std::invalid_argument(
        "EncodeDepthImage: depth_m has " + std::to_string(frame.depth_m.size()) +
        " values for a " + std::to_string(K.width) + "x" +
        std::to_string(K.height) + " image");
  }
  if (!std::isfinite(depth_scale_m) || depth_scale_m <= 0.0) {
    throw std::invalid_argument("EncodeDepthImage: depth scale must be > 0");
  }

  // Quantize, delta-code along each row and lay out little-endian in one
  // pass; the delta is only applied for kZlib16.
  const bool delta = encoding == DepthEncoding::kZlib16;
  std::vector<uint8_t>& raw = Scratch().raw;
  raw.resize(2 * num_pixels);
  for (int v = 0; v < K.height; ++v) {
    uint16_t left = 0;
    for (int u = 0; u < K.width; ++u) {
      const size_t i = static_cast<size_t>(v) * K.width + u;
      const float d = frame.depth_m[i];
      uint16_t units = 0;
      // d > 0 is false for NaN; +0.5 then truncation is round() for
      // positive values, without the libm call.
      if (d > 0.0f) {
        const double q = d / depth_scale_m + 0.5;
        if (q < 65536.0) units = static_cast<uint16_t>(q);
      }
      const uint16_t sample =
          delta ? static_cast<uint16_t>(units - left) : units;
      left = units;
      raw[2 * i] = static_cast<uint8_t>(sample & 0xff);
      raw[2 * i + 1] = static_cast<uint8_t>(sample >> 8);
    }
  }

  graspfill::depth_image_t msg{};
  msg.utime = frame.utime;
  msg.width = K.width;
  msg.height = K.height;
  msg.fx = K.fx;
  msg.fy = K.fy;
  msg.cx = K.cx;
  msg.cy = K.cy;
  msg.depth_scale = depth_scale_m;
  if (delta) {
    msg.encoding = graspfill::depth_image_t::ZLIB16;
    msg.data = Deflate(raw);
  } else {
    msg.encoding = graspfill::depth_image_t::RAW16;
    msg.data = raw;
  }
  msg.num_bytes = static_cast<int32_t>(msg.data.size());
  return EncodeMessage(msg);
}

static bool DecodeDepthImageImpl(const void* data, size_t size, DepthFrame* out,
                                 std::string* error, int64_t max_depth_pixels) {
  if (!CheckBuffer(data, size, out, "depth_image_t", error)) return false;
  // Parsed in place (see the file comment); the layout is depth_image_t's.
  WireReader r(data, size);
  if (!r.Hash(graspfill::depth_image_t::getHash())) {
    SetError(error, "depth_image_t: not a depth_image_t (type hash mismatch "
                    "or truncated)");
    return false;
  }
  int64_t utime;
  int32_t width, height, num_bytes;
  double fx, fy, cx, cy, depth_scale;
  int8_t encoding;
  const uint8_t* payload = nullptr;
  if (!r.I64(&utime) || !r.I32(&width) || !r.I32(&height) || !r.F64(&fx) ||
      !r.F64(&fy) || !r.F64(&cx) || !r.F64(&cy) || !r.F64(&depth_scale) ||
      !r.I8(&encoding) || !r.Count(&num_bytes, 1) ||
      !r.Bytes(static_cast<size_t>(num_bytes), &payload)) {
    SetError(error, "depth_image_t: truncated message");
    return false;
  }
  if (r.remaining() != 0) {
    SetError(error, "depth_image_t: " + std::to_string(r.remaining()) +
                        " trailing bytes");
    return false;
  }
  if (width <= 0 || height <= 0) {
    SetError(error, "depth_image_t: bad image size " + std::to_string(width) +
                        "x" + std::to_string(height),
             MessageError::kBadSize);
    return false;
  }
  // Before anything of the decoded size is allocated.
  const int64_t limit = std::clamp<int64_t>(max_depth_pixels, 1, kMaxDepthPixels);
  if (int64_t{width} * height > limit) {
    SetError(error, "depth_image_t: bad image size " + std::to_string(width) + "x" +
                        std::to_string(height) + ": over the limit of " + std::to_string(limit) +
                        " pixels (max_depth_pixels)",
             MessageError::kBadSize);
    return false;
  }
  {
    std::string why;
    if (!IntrinsicsInRange(CameraIntrinsics{width, height, fx, fy, cx, cy}, &why)) {
      SetError(error, "depth_image_t: bad intrinsics (" + why + ")", MessageError::kBadIntrinsics);
      return false;
    }
  }
  if (!(depth_scale >= kMinDepthScaleM && depth_scale <= kMaxDepthScaleM)) {
    SetError(error, "depth_image_t: bad depth_scale (expected " + FormatLimit(kMinDepthScaleM) +
                        ".." + FormatLimit(kMaxDepthScaleM) + " m per unit)",
             MessageError::kBadDepthScale);
    return false;
  }
  if (!UtimeInRange("depth_image_t", utime, error)) return false;

  const size_t num_pixels = static_cast<size_t>(width) * height;
  const uint8_t* samples = nullptr;  // little-endian uint16, maybe delta-coded
  bool delta = false;
  if (encoding == graspfill::depth_image_t::RAW16) {
    if (static_cast<size_t>(num_bytes) != 2 * num_pixels) {
      SetError(error, "depth_image_t: RAW16 data has " +
                          std::to_string(num_bytes) + " bytes, expected " +
                          std::to_string(2 * num_pixels),
               MessageError::kBadEncoding);
      return false;
    }
    samples = payload;
  } else if (encoding == graspfill::depth_image_t::ZLIB16) {
    // A payload that cannot inflate to the declared image is refused
    // before the scratch grows to it (a few bytes declaring 8 MP).
    if (2 * static_cast<int64_t>(num_pixels) > kMaxDeflateRatio * num_bytes) {
      SetError(error, "depth_image_t: ZLIB16 data of " + std::to_string(num_bytes) +
                          " bytes cannot inflate to the image's " +
                          std::to_string(2 * num_pixels) + " bytes (deflate expands at most " +
                          std::to_string(kMaxDeflateRatio) + " times)",
               MessageError::kBadEncoding);
      return false;
    }
    std::vector<uint8_t>& raw = Scratch().raw;
    raw.resize(2 * num_pixels);  // grows once, then reused
    if (!Inflate(payload, static_cast<size_t>(num_bytes), raw.data(),
                 raw.size(), error)) {
      t_reason = MessageError::kBadEncoding;
      return false;
    }
    samples = raw.data();
    delta = true;
  } else {
    SetError(error, "depth_image_t: unknown encoding " +
                        std::to_string(static_cast<int>(encoding)),
             MessageError::kBadEncoding);
    return false;
  }

  out->utime = utime;
  out->intrinsics.width = width;
  out->intrinsics.height = height;
  out->intrinsics.fx = fx;
  out->intrinsics.fy = fy;
  out->intrinsics.cx = cx;
  out->intrinsics.cy = cy;
  out->depth_m.resize(num_pixels);
  for (int v = 0; v < height; ++v) {
    uint16_t left = 0;
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      const size_t i = row + u;
      uint16_t units = static_cast<uint16_t>(samples[2 * i] |
                                             (samples[2 * i + 1] << 8));
      if (delta) units = static_cast<uint16_t>(units + left);
      left = units;
      // In double, then rounded once: 1500 units of 1 mm is exactly 1.5f.
      out->depth_m[i] = static_cast<float>(units * depth_scale);
    }
  }
  return true;
}

// ---- Gripper state -----------------------------------------------------------

std::vector<uint8_t> EncodeGripperState(const GripperState& state) {
  graspfill::gripper_state_t msg{};
  msg.utime = state.utime;
  msg.frame = graspfill::gripper_state_t::FRAME_CAMERA;
  PoseToWire(state.T_C_G, msg.position, msg.orientation);
  msg.opening_m = state.opening_m;
  msg.num_joints = static_cast<int32_t>(state.joint_values.size());
  msg.joint_values = state.joint_values;
  msg.grasp_id = state.grasp_id;
  return EncodeMessage(msg);
}

static bool DecodeGripperStateImpl(const void* data, size_t size,
                        const Eigen::Isometry3d& T_C_B, GripperState* out,
                        std::string* error) {
  if (!CheckBuffer(data, size, out, "gripper_state_t", error)) return false;
  // Recordings made before grasp_id carry gripper_state_v1_t's layout (and
  // fingerprint): read as grasp_id 0.
  const bool v1 = WireReader(data, size).Hash(graspfill::gripper_state_v1_t::getHash());
  WireReader r(data, size);
  int32_t num_joints;
  if (!r.Hash(v1 ? graspfill::gripper_state_v1_t::getHash()
                 : graspfill::gripper_state_t::getHash()) ||
      !r.Skip(8 + 1 + 3 * 8 + 4 * 8 + 8) || !r.Count(&num_joints, 8) ||
      !r.Skip(8 * static_cast<size_t>(num_joints)) || (!v1 && !r.Skip(8)) ||
      r.remaining() != 0) {
    SetError(error, "gripper_state_t: malformed message");
    return false;
  }
  thread_local graspfill::gripper_state_t msg{};
  // lcm-gen skips an array whose count is 0 without resizing it: clear
  // (keeping capacity) so nothing stale survives from the last message.
  msg.joint_values.clear();
  if (v1) {
    thread_local graspfill::gripper_state_v1_t old{};
    old.joint_values.clear();
    if (!DecodeMessage(data, size, &old, error)) return false;
    msg.utime = old.utime;
    msg.frame = old.frame;
    std::copy(old.position, old.position + 3, msg.position);
    std::copy(old.orientation, old.orientation + 4, msg.orientation);
    msg.opening_m = old.opening_m;
    msg.num_joints = old.num_joints;
    msg.joint_values.assign(old.joint_values.begin(), old.joint_values.end());
    msg.grasp_id = 0;
  } else if (!DecodeMessage(data, size, &msg, error)) {
    return false;
  }

  Eigen::Isometry3d T_F_G;
  if (!PoseFromWire("gripper_state_t", msg.position, msg.orientation, &T_F_G,
                    error)) {
    return false;
  }
  if (!std::isfinite(msg.opening_m) ||
      !AllFinite(msg.joint_values.data(), msg.num_joints)) {
    SetError(error, "gripper_state_t: opening or joint values not finite", MessageError::kBadValue);
    return false;
  }
  if (!UtimeInRange("gripper_state_t", msg.utime, error)) return false;
  if (msg.frame == graspfill::gripper_state_t::FRAME_CAMERA) {
    out->T_C_G = T_F_G;
  } else if (msg.frame == graspfill::gripper_state_t::FRAME_BASE) {
    out->T_C_G = T_C_B * T_F_G;
  } else {
    SetError(error, "gripper_state_t: unknown frame " +
                        std::to_string(static_cast<int>(msg.frame)),
             MessageError::kBadValue);
    return false;
  }
  out->utime = msg.utime;
  out->opening_m = msg.opening_m;
  out->joint_values.assign(msg.joint_values.begin(), msg.joint_values.end());
  out->grasp_id = msg.grasp_id;
  return true;
}

// ---- Object cloud ------------------------------------------------------------

std::vector<uint8_t> EncodeObjectCloud(const ObjectCloud& cloud) {
  PackedPoints packed;
  try {
    packed = PackPoints(cloud);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("EncodeObjectCloud: ") + e.what());
  }
  graspfill::object_cloud_t msg{};
  msg.utime = cloud.utime;
  msg.seq = cloud.seq;
  msg.frame_name = cloud.frame_name;
  PoseToWire(cloud.T_C_G, msg.position, msg.orientation);
  msg.num_points = static_cast<int32_t>(cloud.points_G.size());
  for (int k = 0; k < 3; ++k) msg.origin[k] = packed.origin[k];
  msg.step_m = packed.step_m;
  msg.has_normals = packed.has_normals ? 1 : 0;
  msg.num_packed_bytes = static_cast<int32_t>(packed.deflated.size());
  msg.packed_points = std::move(packed.deflated);
  const SafeBound& bound = cloud.safe_bound;
  if (!bound.empty() && static_cast<size_t>(bound.nx) * bound.ny * bound.nz > 8 * bound.bits.size()) {
    throw std::invalid_argument("EncodeObjectCloud: the safe bound's bits do not cover its grid");
  }
  for (int k = 0; k < 3; ++k) msg.bound_origin[k] = bound.origin_G[k];
  msg.bound_voxel_m = bound.voxel_m;
  msg.bound_nx = bound.nx;
  msg.bound_ny = bound.ny;
  msg.bound_nz = bound.nz;
  msg.bound_num_bytes = static_cast<int32_t>(bound.bits.size());
  msg.bound_bits.assign(bound.bits.begin(), bound.bits.end());
  msg.num_holes = static_cast<int32_t>(cloud.holes.size());
  msg.holes.resize(cloud.holes.size());
  for (size_t i = 0; i < cloud.holes.size(); ++i) {
    const HoleSummary& h = cloud.holes[i];
    graspfill::hole_t& m = msg.holes[i];
    m.kind = static_cast<int8_t>(h.kind);
    m.boundary_points = h.boundary_points;
    for (int k = 0; k < 3; ++k) {
      m.box_min[k] = h.box_min_G[k];
      m.box_max[k] = h.box_max_G[k];
    }
    m.points_added = h.points_added;
    m.unobserved = h.unobserved ? 1 : 0;
    m.confidence = h.confidence;
  }
  msg.num_timings = static_cast<int32_t>(cloud.timings.size());
  for (const StageTiming& t : cloud.timings) {
    msg.timing_names.push_back(t.stage);
    msg.timing_ms.push_back(t.ms);
  }
  msg.grasp_id = cloud.grasp_id;
  msg.is_final = cloud.is_final ? 1 : 0;
  return EncodeMessage(msg);
}

static bool DecodeObjectCloudImpl(const void* data, size_t size, ObjectCloud* out,
                       std::string* error) {
  if (!CheckBuffer(data, size, out, "object_cloud_t", error)) return false;
  // Walk the whole message so that every count is known to fit before the
  // generated decoder resizes anything. Layout: object_cloud_t.lcm.
  {
    WireReader r(data, size);
    int32_t num_points, num_packed_bytes, num_holes, num_timings, bound_num_bytes;
    int8_t has_normals;
    constexpr size_t kHoleBytes = 1 + 4 + 3 * 4 + 3 * 4 + 4 + 1 + 4;
    bool ok = r.Hash(graspfill::object_cloud_t::getHash()) && r.Skip(16) &&
              r.SkipString() && r.Skip(7 * 8) && r.I32(&num_points) &&
              r.Skip(4 * 8) && r.I8(&has_normals) &&  // origin, step_m
              r.Count(&num_packed_bytes, 1) && r.Skip(static_cast<size_t>(num_packed_bytes)) &&
              r.Count(&num_holes, kHoleBytes) &&
              r.Skip(kHoleBytes * static_cast<size_t>(num_holes)) &&
              r.Skip(4 * 4 + 3 * 4) && r.Count(&bound_num_bytes, 1) &&  // the safe bound
              r.Skip(static_cast<size_t>(bound_num_bytes)) &&
              r.Count(&num_timings, 4 + 1 + 8);
    for (int32_t i = 0; ok && i < num_timings; ++i) ok = r.SkipString();
    ok = ok && r.Skip(8 * static_cast<size_t>(num_timings)) &&
         r.Skip(8 + 1) &&  // grasp_id, is_final
         r.remaining() == 0;
    if (!ok) {
      SetError(error, "object_cloud_t: malformed message");
      return false;
    }
    if (num_points < 0 || (has_normals != 0 && has_normals != 1)) {
      SetError(error, "object_cloud_t: num_points " + std::to_string(num_points) + ", has_normals " +
                          std::to_string(static_cast<int>(has_normals)));
      return false;
    }
  }
  thread_local graspfill::object_cloud_t msg{};
  // As for gripper_state_t: empty arrays are not resized by lcm-gen.
  msg.packed_points.clear();
  msg.bound_bits.clear();
  msg.timing_ms.clear();
  if (!DecodeMessage(data, size, &msg, error)) return false;

  Eigen::Isometry3d T_C_G;
  if (!PoseFromWire("object_cloud_t", msg.position, msg.orientation, &T_C_G,
                    error)) {
    return false;
  }
  // Into scratch first: `out` is left as it was on a failure.
  thread_local ObjectCloud points;
  std::string why;
  if (!UnpackPoints(msg.origin, msg.step_m, msg.has_normals != 0, static_cast<size_t>(msg.num_points),
                    msg.packed_points.data(), msg.packed_points.size(), &points, &why)) {
    SetError(error, "object_cloud_t: " + why);
    return false;
  }
  if (msg.bound_num_bytes > 0) {
    // In 128 bits: three int32 counts overflow int64 (found by fuzz_object_cloud).
    const __int128 voxels = static_cast<__int128>(msg.bound_nx) * msg.bound_ny * msg.bound_nz;
    if (msg.bound_nx <= 0 || msg.bound_ny <= 0 || msg.bound_nz <= 0 ||
        !(msg.bound_voxel_m > 0.0f) || !std::isfinite(msg.bound_voxel_m) ||
        !std::isfinite(msg.bound_origin[0]) ||
        !std::isfinite(msg.bound_origin[1]) || !std::isfinite(msg.bound_origin[2]) ||
        (voxels + 7) / 8 != msg.bound_num_bytes) {
      SetError(error, "object_cloud_t: inconsistent safe bound (" + std::to_string(msg.bound_nx) +
                          " x " + std::to_string(msg.bound_ny) + " x " + std::to_string(msg.bound_nz) +
                          " voxels, " + std::to_string(msg.bound_num_bytes) + " bytes)");
      return false;
    }
  }
  for (const graspfill::hole_t& h : msg.holes) {
    if (h.kind != graspfill::hole_t::CLAW &&
        h.kind != graspfill::hole_t::MISSING_SURFACE) {
      SetError(error, "object_cloud_t: unknown hole kind " +
                          std::to_string(static_cast<int>(h.kind)));
      return false;
    }
    if ((h.unobserved != 0 && h.unobserved != 1) || !(h.confidence >= 0.0f && h.confidence <= 1.0f)) {
      SetError(error, "object_cloud_t: a hole's unobserved must be 0 or 1 and its confidence in 0..1 (got " +
                          std::to_string(static_cast<int>(h.unobserved)) + ", " +
                          std::to_string(h.confidence) + ")");
      return false;
    }
  }

  out->utime = msg.utime;
  out->seq = msg.seq;
  out->frame_name = msg.frame_name;
  out->T_C_G = T_C_G;
  out->points_G.swap(points.points_G);
  out->normals_G.swap(points.normals_G);
  out->provenance.swap(points.provenance);
  out->confidence.swap(points.confidence);
  SafeBound& bound = out->safe_bound;
  bound = SafeBound{};
  if (msg.bound_num_bytes > 0) {
    bound.origin_G = Eigen::Vector3f(msg.bound_origin[0], msg.bound_origin[1], msg.bound_origin[2]);
    bound.voxel_m = msg.bound_voxel_m;
    bound.nx = msg.bound_nx;
    bound.ny = msg.bound_ny;
    bound.nz = msg.bound_nz;
    bound.bits.assign(msg.bound_bits.begin(), msg.bound_bits.end());
  }
  out->holes.resize(msg.holes.size());
  for (size_t i = 0; i < msg.holes.size(); ++i) {
    const graspfill::hole_t& m = msg.holes[i];
    HoleSummary& h = out->holes[i];
    h.kind = static_cast<HoleKind>(m.kind);
    h.boundary_points = m.boundary_points;
    h.box_min_G = Eigen::Vector3f(m.box_min[0], m.box_min[1], m.box_min[2]);
    h.box_max_G = Eigen::Vector3f(m.box_max[0], m.box_max[1], m.box_max[2]);
    h.points_added = m.points_added;
    h.unobserved = m.unobserved != 0;
    h.confidence = m.confidence;
  }
  out->timings.resize(msg.timing_names.size());
  for (size_t i = 0; i < msg.timing_names.size(); ++i) {
    out->timings[i].stage = msg.timing_names[i];
    out->timings[i].ms = msg.timing_ms[i];
  }
  out->grasp_id = msg.grasp_id;
  out->is_final = msg.is_final != 0;
  return true;
}

// ---- Module status -----------------------------------------------------------

std::vector<uint8_t> EncodeModuleStatus(const ModuleStatus& status) {
  graspfill::module_status_t msg{};
  msg.utime = status.utime;
  msg.frames_in = status.frames_in;
  msg.frames_used = status.frames_used;
  msg.frames_skipped = status.frames_skipped;
  msg.frames_dropped = status.frames_dropped;
  msg.last_frame_ms = status.last_frame_ms;
  msg.state = status.state;
  msg.state_code = static_cast<int8_t>(status.state_code);
  msg.state_detail = status.state_detail;
  msg.frames_skipped_no_pose = status.frames_skipped_no_pose;
  msg.frames_skipped_clock_jump = status.frames_skipped_clock_jump;
  msg.frames_bad = status.frames_bad;
  msg.frames_skipped_refine = status.frames_skipped_refine;
  msg.decode_errors = status.decode_errors;
  msg.clock_jumps = status.clock_jumps;
  msg.repairs_done = status.repairs_done;
  msg.repairs_superseded = status.repairs_superseded;
  msg.repairs_failed = status.repairs_failed;
  msg.grasp_id = status.grasp_id;
  msg.grasps_completed = status.grasps_completed;
  msg.latency_ms_p50 = status.latency_ms_p50;
  msg.latency_ms_p95 = status.latency_ms_p95;
  msg.latency_ms_p99 = status.latency_ms_p99;
  msg.latency_ms_max = status.latency_ms_max;
  msg.clouds_published = status.clouds_published;
  msg.repair_updates = status.repair_updates;
  msg.repairs_full = status.repairs_full;
  msg.update_ms_p50 = status.update_ms_p50;
  msg.update_ms_p99 = status.update_ms_p99;
  msg.full_repair_ms_p50 = status.full_repair_ms_p50;
  msg.full_repair_ms_p99 = status.full_repair_ms_p99;
  msg.rss_mb = status.rss_mb;
  for (size_t i = 1; i < BadMessageCounts::kNumReasons; ++i) {
    msg.bad_message_reasons.push_back(MessageErrorName(static_cast<MessageError>(i)));
    msg.bad_messages.push_back(status.bad_messages.by_reason[i]);
  }
  msg.num_bad_message_reasons = static_cast<int32_t>(msg.bad_messages.size());
  for (size_t i = 1; i < kNumFrameSkipReasons; ++i) {
    msg.skip_reasons.push_back(FrameSkipReasonName(static_cast<FrameSkipReason>(i)));
    msg.frames_skipped_by_reason.push_back(status.frames_skipped_by_reason.by_reason[i]);
  }
  msg.num_skip_reasons = static_cast<int32_t>(msg.frames_skipped_by_reason.size());
  return EncodeMessage(msg);
}

static bool DecodeModuleStatusImpl(const void* data, size_t size, ModuleStatus* out,
                        std::string* error) {
  if (!CheckBuffer(data, size, out, "module_status_t", error)) return false;
  WireReader r(data, size);
  if (!r.Hash(graspfill::module_status_t::getHash()) || !r.Skip(5 * 8 + 8) ||
      !r.SkipString() || !r.Skip(1) || !r.SkipString() || !r.Skip(11 * 8 + 5 * 8 + 7 * 8)) {
    SetError(error, "module_status_t: malformed message");
    return false;
  }
  // Two named count arrays: the bad messages', the skipped frames'.
  bool ok = true;
  for (int array = 0; ok && array < 2; ++array) {
    int32_t num_reasons = 0;
    ok = r.Count(&num_reasons, 4 + 1 + 8);
    for (int32_t i = 0; ok && i < num_reasons; ++i) ok = r.SkipString();
    ok = ok && r.Skip(8 * static_cast<size_t>(num_reasons));
  }
  if (!ok || r.remaining() != 0) {
    SetError(error, "module_status_t: malformed message");
    return false;
  }
  graspfill::module_status_t msg{};
  if (!DecodeMessage(data, size, &msg, error)) return false;
  out->utime = msg.utime;
  out->frames_in = msg.frames_in;
  out->frames_used = msg.frames_used;
  out->frames_skipped = msg.frames_skipped;
  out->frames_dropped = msg.frames_dropped;
  out->last_frame_ms = msg.last_frame_ms;
  out->state = msg.state;
  out->state_code = static_cast<ModuleState>(msg.state_code);
  out->state_detail = msg.state_detail;
  out->frames_skipped_no_pose = msg.frames_skipped_no_pose;
  out->frames_skipped_clock_jump = msg.frames_skipped_clock_jump;
  out->frames_bad = msg.frames_bad;
  out->frames_skipped_refine = msg.frames_skipped_refine;
  out->decode_errors = msg.decode_errors;
  out->clock_jumps = msg.clock_jumps;
  out->repairs_done = msg.repairs_done;
  out->repairs_superseded = msg.repairs_superseded;
  out->repairs_failed = msg.repairs_failed;
  out->grasp_id = msg.grasp_id;
  out->grasps_completed = msg.grasps_completed;
  out->latency_ms_p50 = msg.latency_ms_p50;
  out->latency_ms_p95 = msg.latency_ms_p95;
  out->latency_ms_p99 = msg.latency_ms_p99;
  out->latency_ms_max = msg.latency_ms_max;
  out->clouds_published = msg.clouds_published;
  out->repair_updates = msg.repair_updates;
  out->repairs_full = msg.repairs_full;
  out->update_ms_p50 = msg.update_ms_p50;
  out->update_ms_p99 = msg.update_ms_p99;
  out->full_repair_ms_p50 = msg.full_repair_ms_p50;
  out->full_repair_ms_p99 = msg.full_repair_ms_p99;
  out->rss_mb = msg.rss_mb;
  out->bad_messages = BadMessageCounts{};
  std::array<bool, BadMessageCounts::kNumReasons> seen{};
  for (size_t i = 0; i < msg.bad_message_reasons.size(); ++i) {
    const MessageError reason = MessageErrorFromName(msg.bad_message_reasons[i]);
    const auto index = static_cast<size_t>(reason);
    if (reason == MessageError::kNone || seen[index] || msg.bad_messages[i] < 0) {
      SetError(error, "module_status_t: bad message reason '" + msg.bad_message_reasons[i] +
                          "' unknown, repeated or with a negative count",
               MessageError::kBadValue);
      return false;
    }
    seen[index] = true;
    out->bad_messages.by_reason[index] = msg.bad_messages[i];
  }
  out->frames_skipped_by_reason = FrameSkipCounts{};
  std::array<bool, kNumFrameSkipReasons> skip_seen{};
  for (size_t i = 0; i < msg.skip_reasons.size(); ++i) {
    const std::optional<FrameSkipReason> reason = FrameSkipReasonFromName(msg.skip_reasons[i]);
    const auto index = static_cast<size_t>(reason.value_or(FrameSkipReason::kNone));
    if (!reason || *reason == FrameSkipReason::kNone || skip_seen[index] ||
        msg.frames_skipped_by_reason[i] < 0) {
      SetError(error, "module_status_t: skip reason '" + msg.skip_reasons[i] +
                          "' unknown, repeated or with a negative count",
               MessageError::kBadValue);
      return false;
    }
    skip_seen[index] = true;
    out->frames_skipped_by_reason.by_reason[index] = msg.frames_skipped_by_reason[i];
  }
  return true;
}

// ---- Session description -------------------------------------------------------

namespace {

// The checks shared by the encoder (caller misuse) and the decoder (bad
// input) on the value type; T_C_B's quaternion is checked on the wire.
bool CheckSession(const SessionDescription& s, std::string* error) {
  const char* type = "session_description_t";
  if (s.claw_name.empty()) {
    SetError(error, std::string(type) + ": empty claw_name");
    return false;
  }
  if (!IsPlainClawName(s.claw_name)) {
    SetError(error, std::string(type) + ": claw_name '" + Printable(s.claw_name, 80) +
                        "' is not a plain name (1..256 bytes, no '/', '\\' or control "
                        "characters, not '.' or '..')",
             MessageError::kBadClawName);
    return false;
  }
  if (!s.T_C_B.matrix().allFinite()) {
    SetError(error, std::string(type) + ": T_C_B is not finite");
    return false;
  }
  if (s.intrinsics) {
    const CameraIntrinsics& K = *s.intrinsics;
    if (K.width <= 0 || K.height <= 0 || int64_t{K.width} * K.height > kMaxDepthPixels) {
      SetError(error, std::string(type) + ": bad intrinsics override size " +
                          std::to_string(K.width) + "x" + std::to_string(K.height),
               MessageError::kBadSize);
      return false;
    }
    std::string why;
    if (!IntrinsicsInRange(K, &why)) {
      SetError(error, std::string(type) + ": bad intrinsics override (" + why + ")",
               MessageError::kBadIntrinsics);
      return false;
    }
  }
  if (s.workspace_G) {
    const Eigen::AlignedBox3d& box = *s.workspace_G;
    if (!box.min().allFinite() || !box.max().allFinite() ||
        !(box.min().array() < box.max().array()).all()) {
      SetError(error, std::string(type) + ": workspace box must be finite with min < max");
      return false;
    }
  }
  if (!std::isfinite(s.voxel_m) || s.voxel_m < 0.0) {
    SetError(error, std::string(type) + ": voxel_m must be finite and >= 0 (0 = default)");
    return false;
  }
  return true;
}

}  // namespace

bool IsPlainClawName(const std::string& name) {
  if (name.empty() || name.size() > 256 || name == "." || name == "..") return false;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '/' || c == '\\' || u < 0x20 || u == 0x7f) return false;
  }
  return true;
}

bool SessionWithinLimits(const SessionDescription& s, std::string* why) {
  auto fail = [&](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  const auto number = FormatLimit;
  if (s.workspace_G) {
    static const char* kAxes = "xyz";
    for (int k = 0; k < 3; ++k) {
      for (const double v : {s.workspace_G->min()[k], s.workspace_G->max()[k]}) {
        // Written as an "in range" test so that NaN fails it.
        if (!(v >= -kMaxWorkspaceM && v <= kMaxWorkspaceM)) {
          return fail("asks for a workspace box with " + std::string(1, kAxes[k]) + " " +
                      number(v) + " m, outside -" + number(kMaxWorkspaceM) + ".." +
                      number(kMaxWorkspaceM) + " m");
        }
      }
    }
  }
  if (s.voxel_m != 0.0 && !(s.voxel_m >= kMinVoxelM && s.voxel_m <= kMaxVoxelM)) {
    return fail("asks for a voxel of " + number(s.voxel_m) + " m, outside " + number(kMinVoxelM) +
                ".." + number(kMaxVoxelM) + " m");
  }
  const Eigen::Vector3d t = s.T_C_B.translation();
  if (!(t.cwiseAbs().maxCoeff() <= kMaxHandEyeTranslationM)) {
    return fail("asks for a hand-eye T_C_B translated by " + number(t.cwiseAbs().maxCoeff()) +
                " m, beyond " + number(kMaxHandEyeTranslationM) + " m");
  }
  return true;
}

std::string SoftwareVersion() { return std::string("graspfill ") + GRASPFILL_VERSION; }

std::vector<uint8_t> EncodeSessionDescription(const SessionDescription& session) {
  std::string error;
  if (!CheckSession(session, &error)) {
    throw std::invalid_argument("EncodeSessionDescription: " + error);
  }
  using Msg = graspfill::session_description_t;
  Msg msg{};
  msg.utime = session.utime;
  msg.software_version = session.software_version;
  switch (session.claw_kind) {
    case SessionClawKind::kBuiltin: msg.claw_kind = Msg::CLAW_BUILTIN; break;
    case SessionClawKind::kDescription: msg.claw_kind = Msg::CLAW_DESCRIPTION; break;
    case SessionClawKind::kUrdf: msg.claw_kind = Msg::CLAW_URDF; break;
  }
  msg.claw_name = session.claw_name;
  msg.claw_text = session.claw_text;
  msg.claw_source = session.claw_source;
  msg.claw_mesh_root = session.claw_mesh_root;
  PoseToWire(session.T_C_B, msg.T_C_B_position, msg.T_C_B_orientation);
  if (session.intrinsics) {
    const CameraIntrinsics& K = *session.intrinsics;
    msg.has_intrinsics = 1;
    msg.width = K.width;
    msg.height = K.height;
    msg.fx = K.fx;
    msg.fy = K.fy;
    msg.cx = K.cx;
    msg.cy = K.cy;
  }
  if (session.workspace_G) {
    msg.has_workspace_box = 1;
    for (int k = 0; k < 3; ++k) {
      msg.workspace_min[k] = session.workspace_G->min()[k];
      msg.workspace_max[k] = session.workspace_G->max()[k];
    }
  }
  msg.voxel_m = session.voxel_m;
  return EncodeMessage(msg);
}

static bool DecodeSessionDescriptionImpl(const void* data, size_t size, SessionDescription* out,
                              std::string* error) {
  using Msg = graspfill::session_description_t;
  if (!CheckBuffer(data, size, out, "session_description_t", error)) return false;
  // Layout: session_description_t.lcm. Every string length is checked
  // against the bytes left before the generated decoder reads it.
  {
    WireReader r(data, size);
    const bool ok = r.Hash(Msg::getHash()) && r.Skip(8) && r.SkipString() &&  // version
                    r.Skip(1) && r.SkipString() && r.SkipString() &&            // name, text
                    r.SkipString() && r.SkipString() &&                         // source, root
                    r.Skip(7 * 8) && r.Skip(1 + 2 * 4 + 4 * 8) &&               // T_C_B, K
                    r.Skip(1 + 6 * 8) && r.Skip(8) && r.remaining() == 0;       // box, voxel
    if (!ok) {
      SetError(error, "session_description_t: malformed message");
      return false;
    }
  }
  Msg msg{};
  if (!DecodeMessage(data, size, &msg, error)) return false;

  SessionDescription s;
  s.utime = msg.utime;
  s.software_version = msg.software_version;
  if (msg.claw_kind == Msg::CLAW_BUILTIN) {
    s.claw_kind = SessionClawKind::kBuiltin;
  } else if (msg.claw_kind == Msg::CLAW_DESCRIPTION) {
    s.claw_kind = SessionClawKind::kDescription;
  } else if (msg.claw_kind == Msg::CLAW_URDF) {
    s.claw_kind = SessionClawKind::kUrdf;
  } else {
    SetError(error, "session_description_t: unknown claw_kind " +
                        std::to_string(static_cast<int>(msg.claw_kind)));
    return false;
  }
  s.claw_name = msg.claw_name;
  s.claw_text = msg.claw_text;
  s.claw_source = msg.claw_source;
  s.claw_mesh_root = msg.claw_mesh_root;
  if (!PoseFromWire("session_description_t: T_C_B", msg.T_C_B_position, msg.T_C_B_orientation,
                    &s.T_C_B, error)) {
    return false;
  }
  if ((msg.has_intrinsics != 0 && msg.has_intrinsics != 1) ||
      (msg.has_workspace_box != 0 && msg.has_workspace_box != 1)) {
    SetError(error, "session_description_t: has_intrinsics and has_workspace_box must be 0 or 1");
    return false;
  }
  if (msg.has_intrinsics == 1) {
    s.intrinsics = CameraIntrinsics{msg.width, msg.height, msg.fx, msg.fy, msg.cx, msg.cy};
  }
  if (msg.has_workspace_box == 1) {
    s.workspace_G = Eigen::AlignedBox3d(
        Eigen::Vector3d(msg.workspace_min[0], msg.workspace_min[1], msg.workspace_min[2]),
        Eigen::Vector3d(msg.workspace_max[0], msg.workspace_max[1], msg.workspace_max[2]));
  }
  s.voxel_m = msg.voxel_m;
  if (!CheckSession(s, error)) return false;
  *out = std::move(s);
  return true;
}

// ---- Public decoders: the reason of a failure ---------------------------------

namespace {
template <typename F>
bool WithReason(MessageError* reason, F decode) {
  t_reason = MessageError::kNone;
  const bool ok = decode();
  if (reason != nullptr) {
    *reason = ok ? MessageError::kNone
                 : (t_reason == MessageError::kNone ? MessageError::kMalformed : t_reason);
  }
  return ok;
}
}  // namespace

bool DecodeDepthImage(const void* data, size_t size, DepthFrame* out, std::string* error,
                      MessageError* reason, int64_t max_depth_pixels) {
  return WithReason(reason,
                    [&] { return DecodeDepthImageImpl(data, size, out, error, max_depth_pixels); });
}
bool DecodeGripperState(const void* data, size_t size, const Eigen::Isometry3d& T_C_B,
                        GripperState* out, std::string* error, MessageError* reason) {
  return WithReason(reason, [&] { return DecodeGripperStateImpl(data, size, T_C_B, out, error); });
}
bool DecodeObjectCloud(const void* data, size_t size, ObjectCloud* out, std::string* error,
                       MessageError* reason) {
  return WithReason(reason, [&] { return DecodeObjectCloudImpl(data, size, out, error); });
}
bool DecodeModuleStatus(const void* data, size_t size, ModuleStatus* out, std::string* error,
                        MessageError* reason) {
  return WithReason(reason, [&] { return DecodeModuleStatusImpl(data, size, out, error); });
}
bool DecodeSessionDescription(const void* data, size_t size, SessionDescription* out,
                              std::string* error, MessageError* reason) {
  return WithReason(reason,
                    [&] { return DecodeSessionDescriptionImpl(data, size, out, error); });
}

const char* MessageErrorName(MessageError reason) {
  switch (reason) {
    case MessageError::kNone: return "none";
    case MessageError::kMalformed: return "malformed";
    case MessageError::kBadSize: return "bad_size";
    case MessageError::kBadIntrinsics: return "bad_intrinsics";
    case MessageError::kBadDepthScale: return "bad_depth_scale";
    case MessageError::kBadEncoding: return "bad_encoding";
    case MessageError::kBadPose: return "bad_pose";
    case MessageError::kBadValue: return "bad_value";
    case MessageError::kBadTimestamp: return "bad_timestamp";
    case MessageError::kIntrinsicsMismatch: return "intrinsics_mismatch";
    case MessageError::kNonMonotonicTime: return "non_monotonic_time";
    case MessageError::kBadClawName: return "bad_claw_name";
    case MessageError::kOutOfLimits: return "out_of_limits";
    case MessageError::kClawUnloadable: return "claw_unloadable";
    case MessageError::kCount: break;
  }
  return "unknown";
}

MessageError MessageErrorFromName(const std::string& name) {
  for (size_t i = 1; i < BadMessageCounts::kNumReasons; ++i) {
    const auto reason = static_cast<MessageError>(i);
    if (name == MessageErrorName(reason)) return reason;
  }
  return MessageError::kNone;
}

bool IntrinsicsInRange(const CameraIntrinsics& K, std::string* why) {
  auto fail = [&](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  // Written as "in range" tests so that NaN fails them.
  if (!(K.fx >= kMinFocalPx && K.fx <= kMaxFocalPx && K.fy >= kMinFocalPx &&
        K.fy <= kMaxFocalPx)) {
    return fail("focal lengths must be " + FormatLimit(kMinFocalPx) + ".." +
                FormatLimit(kMaxFocalPx) + " px");
  }
  const double w = K.width, h = K.height;
  if (!(K.cx >= -w && K.cx <= 2.0 * w && K.cy >= -h && K.cy <= 2.0 * h)) {
    return fail("principal point must be within one image size of the image");
  }
  return true;
}

}  // namespace graspfill::io
