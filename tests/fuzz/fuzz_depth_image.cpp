// SPDX-License-Identifier: BSD-3-Clause
// depth_image_t decoder on arbitrary bytes; what decodes re-encodes and
// decodes again to the same image size, intrinsics and time.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/messages.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  DepthFrame frame;
  std::string error;
  io::MessageError reason;
  if (!io::DecodeDepthImage(data, size, &frame, &error, &reason)) {
    FUZZ_CHECK(reason != io::MessageError::kNone);
    FUZZ_CHECK(!error.empty());
    return 0;
  }
  FUZZ_CHECK(reason == io::MessageError::kNone);
  const CameraIntrinsics& K = frame.intrinsics;
  FUZZ_CHECK(frame.depth_m.size() == static_cast<size_t>(K.width) * K.height);
  FUZZ_CHECK(io::IntrinsicsInRange(K, nullptr));
  for (float d : frame.depth_m) FUZZ_CHECK(std::isfinite(d) && d >= 0.0f);
  for (io::DepthEncoding encoding : {io::DepthEncoding::kRaw16, io::DepthEncoding::kZlib16}) {
    const std::vector<uint8_t> bytes = io::EncodeDepthImage(frame, encoding, 0.001);
    DepthFrame back;
    FUZZ_CHECK(io::DecodeDepthImage(bytes.data(), bytes.size(), &back, &error));
    FUZZ_CHECK(back.intrinsics == frame.intrinsics);
    FUZZ_CHECK(back.utime == frame.utime);
    FUZZ_CHECK(back.depth_m.size() == frame.depth_m.size());
  }
  return 0;
}
