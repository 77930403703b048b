// SPDX-License-Identifier: BSD-3-Clause
// Bounded memory per depth message (issue 36): an image over the pixel
// limit, a ZLIB16 payload too short for its declared image and a zlib bomb
// are refused before anything of the size they declare is allocated. This
// binary replaces the global operator new to see the largest allocation
// made while a message is decoded.
#include <zlib.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <thread>
#include <vector>

#include <graspfill/depth_image_t.hpp>

#include "graspfill/io/messages.hpp"

namespace {
std::atomic<bool> g_tracking{false};
std::atomic<size_t> g_largest{0};
}  // namespace

void* operator new(size_t bytes) {
  if (g_tracking.load(std::memory_order_relaxed)) {
    size_t seen = g_largest.load(std::memory_order_relaxed);
    while (bytes > seen && !g_largest.compare_exchange_weak(seen, bytes)) {
    }
  }
  void* p = std::malloc(bytes != 0 ? bytes : 1);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }

namespace graspfill::io {
namespace {

constexpr size_t kMiB = size_t{1} << 20;

// The largest single allocation `decode` makes, run on a thread of its
// own: the decoder's per-thread scratch starts empty (an earlier test's
// large frame cannot hide an allocation).
template <typename F>
size_t LargestAllocationOf(F decode) {
  std::thread worker([&] {
    g_largest = 0;
    g_tracking = true;
    decode();
    g_tracking = false;
  });
  worker.join();
  return g_largest;
}

std::vector<uint8_t> DepthMessage(int width, int height, int8_t encoding, std::vector<uint8_t> data) {
  graspfill::depth_image_t msg{};
  msg.utime = 1000;
  msg.width = width;
  msg.height = height;
  msg.fx = msg.fy = 500.0;
  msg.cx = width / 2.0;
  msg.cy = height / 2.0;
  msg.depth_scale = 0.001;
  msg.encoding = encoding;
  msg.num_bytes = static_cast<int32_t>(data.size());
  msg.data = std::move(data);
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// A complete zlib stream of `raw_bytes` zero bytes (a zlib bomb when it
// is far more than the image it claims to be), deflated 1 MiB at a time.
std::vector<uint8_t> ZerosCompressed(size_t raw_bytes) {
  z_stream zs{};
  EXPECT_EQ(deflateInit(&zs, 9), Z_OK);
  const std::vector<uint8_t> zeros(kMiB, 0);
  std::vector<uint8_t> out;
  std::vector<uint8_t> chunk(64 << 10);
  size_t left = raw_bytes;
  int rc = Z_OK;
  do {
    const size_t in = std::min(left, zeros.size());
    zs.next_in = const_cast<Bytef*>(zeros.data());
    zs.avail_in = static_cast<uInt>(in);
    left -= in;
    const int flush = left == 0 ? Z_FINISH : Z_NO_FLUSH;
    do {
      zs.next_out = chunk.data();
      zs.avail_out = static_cast<uInt>(chunk.size());
      rc = deflate(&zs, flush);
      out.insert(out.end(), chunk.data(), chunk.data() + (chunk.size() - zs.avail_out));
    } while (zs.avail_out == 0);
  } while (left > 0);
  EXPECT_EQ(rc, Z_STREAM_END);
  deflateEnd(&zs);
  return out;
}

DepthFrame NoisyFrame(int width, int height) {
  DepthFrame frame;
  frame.utime = 1000;
  frame.intrinsics = {width, height, 500.0, 500.0, width / 2.0, height / 2.0};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> depth_m(0.4f, 0.9f);
  frame.depth_m.resize(static_cast<size_t>(width) * height);
  for (float& d : frame.depth_m) d = depth_m(rng);
  return frame;
}

TEST(DepthLimits, DefaultIsEightMegapixelsWithinTheCeiling) {
  EXPECT_EQ(kDefaultMaxDepthPixels, 8388608);
  EXPECT_LE(kDefaultMaxDepthPixels, kMaxDepthPixels);
}

// A few bytes declaring 100000 x 100000: refused before anything is allocated.
TEST(DepthLimits, HugeDeclaredImageIsRefusedWithoutAllocatingIt) {
  const auto bytes = DepthMessage(100000, 100000, graspfill::depth_image_t::RAW16, {1, 2, 3, 4});
  DepthFrame out;
  std::string error;
  MessageError reason = MessageError::kNone;
  bool ok = true;
  const size_t largest =
      LargestAllocationOf([&] { ok = DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason); });
  EXPECT_FALSE(ok);
  EXPECT_EQ(reason, MessageError::kBadSize) << error;
  EXPECT_NE(error.find("bad image size 100000x100000: over the limit of 8388608"), std::string::npos)
      << error;
  EXPECT_LT(largest, 64u << 10);
  EXPECT_EQ(out.depth_m.capacity(), 0u);
}

// The probe: valid 4096 x 4096 frames (67 MB decoded each). Over
// the default limit they are refused before decoding; a config that
// raises the limit takes them.
TEST(DepthLimits, FrameOverTheConfiguredLimitIsRefusedBeforeItsDecodedSizeIsAllocated) {
  const DepthFrame big = NoisyFrame(4096, 4096);
  const auto raw = EncodeDepthImage(big, DepthEncoding::kRaw16);  // 32 MiB
  DepthFrame out;
  std::string error;
  MessageError reason = MessageError::kNone;
  bool ok = true;
  size_t largest =
      LargestAllocationOf([&] { ok = DecodeDepthImage(raw.data(), raw.size(), &out, &error, &reason); });
  EXPECT_FALSE(ok);
  EXPECT_EQ(reason, MessageError::kBadSize);
  EXPECT_NE(error.find("bad image size 4096x4096: over the limit of 8388608 pixels (max_depth_pixels)"),
            std::string::npos)
      << error;
  EXPECT_LT(largest, kMiB);

  // Raised to the ceiling: decoded, 4 bytes a pixel.
  largest = LargestAllocationOf(
      [&] { ok = DecodeDepthImage(raw.data(), raw.size(), &out, &error, &reason, kMaxDepthPixels); });
  EXPECT_TRUE(ok) << error;
  EXPECT_EQ(out.depth_m.size(), size_t{4096} * 4096);
  EXPECT_GE(largest, size_t{4096} * 4096 * sizeof(float));

  // A limit of its own: one pixel under a 640 x 480 frame refuses it.
  const auto vga = EncodeDepthImage(NoisyFrame(640, 480), DepthEncoding::kZlib16);
  EXPECT_FALSE(DecodeDepthImage(vga.data(), vga.size(), &out, &error, &reason, 640 * 480 - 1));
  EXPECT_EQ(reason, MessageError::kBadSize);
  EXPECT_TRUE(DecodeDepthImage(vga.data(), vga.size(), &out, &error, &reason, 640 * 480)) << error;
  // Beyond the ceiling counts as the ceiling.
  EXPECT_TRUE(DecodeDepthImage(vga.data(), vga.size(), &out, &error, &reason, int64_t{1} << 40));
}

// 100 bytes of ZLIB16 claiming 2048 x 2048 (8 MiB inflated): no deflate
// stream that short inflates that far, so nothing is allocated for it.
TEST(DepthLimits, ZlibPayloadTooShortForItsImageIsRefusedBeforeAllocating) {
  std::vector<uint8_t> payload = ZerosCompressed(1000);
  payload.resize(100, 0);
  const auto bytes = DepthMessage(2048, 2048, graspfill::depth_image_t::ZLIB16, payload);
  DepthFrame out;
  std::string error;
  MessageError reason = MessageError::kNone;
  bool ok = true;
  const size_t largest =
      LargestAllocationOf([&] { ok = DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason); });
  EXPECT_FALSE(ok);
  EXPECT_EQ(reason, MessageError::kBadEncoding);
  EXPECT_NE(error.find("ZLIB16 data of 100 bytes cannot inflate to the image's 8388608 bytes"),
            std::string::npos)
      << error;
  EXPECT_LT(largest, kMiB);
}

// A zlib bomb: 256 MiB of zeros in a ~0.25 MB stream, declared as a
// 1024 x 1024 image. Inflating stops at the declared 2 MiB: refused, and
// nothing larger than the declared image is allocated.
TEST(DepthLimits, ZlibBombInflatesNoFurtherThanTheDeclaredImage) {
  const std::vector<uint8_t> bomb = ZerosCompressed(size_t{256} << 20);
  ASSERT_LT(bomb.size(), 1u << 20);
  const auto bytes = DepthMessage(1024, 1024, graspfill::depth_image_t::ZLIB16, bomb);
  DepthFrame out;
  std::string error;
  MessageError reason = MessageError::kNone;
  bool ok = true;
  const size_t largest =
      LargestAllocationOf([&] { ok = DecodeDepthImage(bytes.data(), bytes.size(), &out, &error, &reason); });
  EXPECT_FALSE(ok);
  EXPECT_EQ(reason, MessageError::kBadEncoding);
  EXPECT_NE(error.find("corrupt zlib data"), std::string::npos) << error;
  EXPECT_LE(largest, 2 * size_t{1024} * 1024);
  EXPECT_EQ(out.depth_m.capacity(), 0u);  // nothing decoded into the frame
}

// The short-payload check never refuses a real stream: an all-zero frame
// (the best case for deflate) of the default limit's size decodes.
TEST(DepthLimits, MostCompressibleRealFrameStillDecodes) {
  DepthFrame zeros;
  zeros.utime = 5;
  zeros.intrinsics = {4096, 2048, 500.0, 500.0, 2048.0, 1024.0};
  zeros.depth_m.assign(size_t{4096} * 2048, 0.0f);
  const auto bytes = EncodeDepthImage(zeros, DepthEncoding::kZlib16);
  DepthFrame out;
  std::string error;
  ASSERT_TRUE(DecodeDepthImage(bytes.data(), bytes.size(), &out, &error)) << error;
  EXPECT_EQ(out.depth_m.size(), zeros.depth_m.size());
  EXPECT_TRUE(std::all_of(out.depth_m.begin(), out.depth_m.end(), [](float d) { return d == 0; }));
}

}  // namespace
}  // namespace graspfill::io
