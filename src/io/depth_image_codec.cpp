// SPDX-License-Identifier: BSD-3-Clause
// depth_image_t <-> DepthFrame: parsed in place and inflated into per-thread
// scratch (30 Hz; the steady state allocates nothing).
#include "graspfill/io/messages.hpp"

#include "wire.hpp"

#include <zlib.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include <graspfill/depth_image_t.hpp>

namespace graspfill::io {
using namespace wire;
namespace {

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

ZlibScratch& CodecScratch() {
  thread_local ZlibScratch scratch;
  return scratch;
}

// Inflates exactly `out_size` bytes from a complete zlib stream; never
// writes past `out_size` (a stream that would inflate to more, a zlib bomb,
// stops there and is refused).
bool Inflate(const uint8_t* in, size_t in_size, uint8_t* out, size_t out_size, std::string* error) {
  ZlibScratch& s = CodecScratch();
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
    SetError(error,
             std::string("depth_image_t: corrupt zlib data (") + (zs.msg ? zs.msg : "size mismatch") + ")");
    return false;
  }
  if (zs.avail_out != 0 || zs.avail_in != 0) {
    SetError(error, "depth_image_t: zlib data does not match the image size");
    return false;
  }
  return true;
}

std::vector<uint8_t> Deflate(const std::vector<uint8_t>& raw) {
  ZlibScratch& s = CodecScratch();
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

std::vector<uint8_t> EncodeDepthImage(const DepthFrame& frame, DepthEncoding encoding, double depth_scale_m) {
  const CameraIntrinsics& K = frame.intrinsics;
  if (K.width <= 0 || K.height <= 0 || int64_t{K.width} * K.height > kMaxDepthPixels) {
    throw std::invalid_argument("EncodeDepthImage: bad image size " + std::to_string(K.width) + "x" +
                                std::to_string(K.height));
  }
  const size_t num_pixels = static_cast<size_t>(K.width) * K.height;
  if (frame.depth_m.size() != num_pixels) {
    throw std::invalid_argument("EncodeDepthImage: depth_m has " + std::to_string(frame.depth_m.size()) +
                                " values for a " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                                " image");
  }
  if (!std::isfinite(depth_scale_m) || depth_scale_m <= 0.0) {
    throw std::invalid_argument("EncodeDepthImage: depth scale must be > 0");
  }

  // Quantize, delta-code along each row and lay out little-endian in one
  // pass; the delta is only applied for kZlib16.
  const bool delta = encoding == DepthEncoding::kZlib16;
  std::vector<uint8_t>& raw = CodecScratch().raw;
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
      const uint16_t sample = delta ? static_cast<uint16_t>(units - left) : units;
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

static bool DecodeDepthImageImpl(const void* data, size_t size, DepthFrame* out, std::string* error,
                                 int64_t max_depth_pixels) {
  if (!CheckBuffer(data, size, out, "depth_image_t", error)) return false;
  // Parsed in place (see the file comment); the layout is depth_image_t's.
  WireReader r(data, size);
  if (!r.Hash(graspfill::depth_image_t::getHash())) {
    SetError(error,
             "depth_image_t: not a depth_image_t (type hash mismatch "
             "or truncated)");
    return false;
  }
  int64_t utime;
  int32_t width, height, num_bytes;
  double fx, fy, cx, cy, depth_scale;
  int8_t encoding;
  const uint8_t* payload = nullptr;
  if (!r.I64(&utime) || !r.I32(&width) || !r.I32(&height) || !r.F64(&fx) || !r.F64(&fy) || !r.F64(&cx) ||
      !r.F64(&cy) || !r.F64(&depth_scale) || !r.I8(&encoding) || !r.Count(&num_bytes, 1) ||
      !r.Bytes(static_cast<size_t>(num_bytes), &payload)) {
    SetError(error, "depth_image_t: truncated message");
    return false;
  }
  if (r.remaining() != 0) {
    SetError(error, "depth_image_t: " + std::to_string(r.remaining()) + " trailing bytes");
    return false;
  }
  if (width <= 0 || height <= 0) {
    SetError(error, "depth_image_t: bad image size " + std::to_string(width) + "x" + std::to_string(height),
             MessageError::kBadSize);
    return false;
  }
  // Before anything of the decoded size is allocated.
  const int64_t limit = std::clamp<int64_t>(max_depth_pixels, 1, kMaxDepthPixels);
  if (int64_t{width} * height > limit) {
    SetError(error,
             "depth_image_t: bad image size " + std::to_string(width) + "x" + std::to_string(height) +
                 ": over the limit of " + std::to_string(limit) + " pixels (max_depth_pixels)",
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
    SetError(error,
             "depth_image_t: bad depth_scale (expected " + FormatLimit(kMinDepthScaleM) + ".." +
                 FormatLimit(kMaxDepthScaleM) + " m per unit)",
             MessageError::kBadDepthScale);
    return false;
  }
  if (!UtimeInRange("depth_image_t", utime, error)) return false;

  const size_t num_pixels = static_cast<size_t>(width) * height;
  const uint8_t* samples = nullptr;  // little-endian uint16, maybe delta-coded
  bool delta = false;
  if (encoding == graspfill::depth_image_t::RAW16) {
    if (static_cast<size_t>(num_bytes) != 2 * num_pixels) {
      SetError(error,
               "depth_image_t: RAW16 data has " + std::to_string(num_bytes) + " bytes, expected " +
                   std::to_string(2 * num_pixels),
               MessageError::kBadEncoding);
      return false;
    }
    samples = payload;
  } else if (encoding == graspfill::depth_image_t::ZLIB16) {
    // A payload that cannot inflate to the declared image is refused
    // before the scratch grows to it (a few bytes declaring 8 MP).
    if (2 * static_cast<int64_t>(num_pixels) > kMaxDeflateRatio * num_bytes) {
      SetError(error,
               "depth_image_t: ZLIB16 data of " + std::to_string(num_bytes) +
                   " bytes cannot inflate to the image's " + std::to_string(2 * num_pixels) +
                   " bytes (deflate expands at most " + std::to_string(kMaxDeflateRatio) + " times)",
               MessageError::kBadEncoding);
      return false;
    }
    std::vector<uint8_t>& raw = CodecScratch().raw;
    raw.resize(2 * num_pixels);  // grows once, then reused
    if (!Inflate(payload, static_cast<size_t>(num_bytes), raw.data(), raw.size(), error)) {
      FailureReason() = MessageError::kBadEncoding;
      return false;
    }
    samples = raw.data();
    delta = true;
  } else {
    SetError(error, "depth_image_t: unknown encoding " + std::to_string(static_cast<int>(encoding)),
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
      uint16_t units = static_cast<uint16_t>(samples[2 * i] | (samples[2 * i + 1] << 8));
      if (delta) units = static_cast<uint16_t>(units + left);
      left = units;
      // In double, then rounded once: 1500 units of 1 mm is exactly 1.5f.
      out->depth_m[i] = static_cast<float>(units * depth_scale);
    }
  }
  return true;
}

bool DecodeDepthImage(const void* data, size_t size, DepthFrame* out, std::string* error,
                      MessageError* reason, int64_t max_depth_pixels) {
  return WithReason(reason, [&] { return DecodeDepthImageImpl(data, size, out, error, max_depth_pixels); });
}

bool IntrinsicsInRange(const CameraIntrinsics& K, std::string* why) {
  auto fail = [&](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  // Written as "in range" tests so that NaN fails them.
  if (!(K.fx >= kMinFocalPx && K.fx <= kMaxFocalPx && K.fy >= kMinFocalPx && K.fy <= kMaxFocalPx)) {
    return fail("focal lengths must be " + FormatLimit(kMinFocalPx) + ".." + FormatLimit(kMaxFocalPx) +
                " px");
  }
  const double w = K.width, h = K.height;
  if (!(K.cx >= -w && K.cx <= 2.0 * w && K.cy >= -h && K.cy <= 2.0 * h)) {
    return fail("principal point must be within one image size of the image");
  }
  return true;
}

}  // namespace graspfill::io
