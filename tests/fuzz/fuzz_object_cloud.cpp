// SPDX-License-Identifier: BSD-3-Clause
// object_cloud_t decoder on arbitrary bytes, with an encode round trip.
#include <algorithm>
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
  // The points are packed in steps (object_cloud_t.lcm): packing decoded
  // points again moves each by less than a step, plus float rounding.
  FUZZ_CHECK(back.points_G.size() == cloud.points_G.size());
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& p : cloud.points_G) box.extend(p.cast<double>());
  // The step is 50 um, or the power-of-two multiple that spans the cloud
  // in 32766 steps each way (under twice the half extent over 32766).
  const double step = box.isEmpty() ? 5e-5 : std::max(5e-5, box.sizes().maxCoeff() / 32766.0 * 2.0);
  for (size_t i = 0; i < cloud.points_G.size(); ++i) {
    const double slack = 0.5 * step + 1e-6 * cloud.points_G[i].cast<double>().norm();
    FUZZ_CHECK((back.points_G[i] - cloud.points_G[i]).cast<double>().cwiseAbs().maxCoeff() <= slack);
  }
  FUZZ_CHECK(back.provenance == cloud.provenance);
  FUZZ_CHECK(back.confidence.size() == cloud.points_G.size());
  FUZZ_CHECK(back.holes.size() == cloud.holes.size());
  FUZZ_CHECK(back.timings.size() == cloud.timings.size());
  FUZZ_CHECK(back.safe_bound.bits == cloud.safe_bound.bits);
  FUZZ_CHECK(back.utime == cloud.utime && back.seq == cloud.seq && back.frame_name == cloud.frame_name);
  return 0;
}
