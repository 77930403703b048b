// object_cloud_t decoder on arbitrary bytes, with an encode round trip.
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"
#include "graspfill/io/messages.hpp"

using namespace graspfill;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ObjectCloud cloud;
  std::string error;
  io::MessageError reason;
  if (!io::DecodeObjectCloud(data, size, &cloud, &error, &reason)) {
    FUZZ_CHECK(reason != io::MessageError::kNone && !error.empty());
    return 0;
  }
  FUZZ_CHECK(cloud.provenance.size() == cloud.points_G.size());
  FUZZ_CHECK(cloud.normals_G.empty() || cloud.normals_G.size() == cloud.points_G.size());
  const std::vector<uint8_t> bytes = io::EncodeObjectCloud(cloud);
  ObjectCloud back;
  FUZZ_CHECK(io::DecodeObjectCloud(bytes.data(), bytes.size(), &back, &error));
  FUZZ_CHECK(back.points_G == cloud.points_G);
  FUZZ_CHECK(back.provenance == cloud.provenance);
  FUZZ_CHECK(back.confidence.size() == cloud.points_G.size());
  FUZZ_CHECK(back.holes.size() == cloud.holes.size());
  FUZZ_CHECK(back.timings.size() == cloud.timings.size());
  FUZZ_CHECK(back.safe_bound.bits == cloud.safe_bound.bits);
  FUZZ_CHECK(back.utime == cloud.utime && back.seq == cloud.seq && back.frame_name == cloud.frame_name);
  return 0;
}
