// SPDX-License-Identifier: BSD-3-Clause
// The repair on small clouds: a fixed protocol cylinder (holes and all, of
// 2,000 or 800 points) plus up to 256 points from the input as float
// triples (any value: NaN, inf, 1e38, subnormals), best or paper mode. Contract: non-finite
// input is std::invalid_argument; otherwise every input point comes back
// first and unchanged, then only finite added points.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "fuzz_check.hpp"
#include "repair_steps.hpp"
#include "synth/paper_protocol.hpp"

using namespace graspfill;

namespace {
// A protocol cylinder of `num_points` (holes and all).
repair::PointList ProtocolCylinder(int num_points) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = num_points;
  return synth::MakePaperProtocolCloud(config).holey;
}
// 2,000 points: its claw holes are filled by the local sheets (~20 ms a
// repair). 800 points: too sparse for them, so best mode leaves the holes
// open. Paper mode fills them from its Poisson surface, so that path is
// fuzzed too.
const repair::PointList& BaseCloud(bool sparse) {
  static const repair::PointList dense = ProtocolCylinder(2000);
  static const repair::PointList thin = ProtocolCylinder(800);
  return sparse ? thin : dense;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t flags = data[0];
  ObjectCloud cloud;
  if (flags & 1) cloud.points_G = BaseCloud((flags & 8) != 0);
  const size_t num = std::min<size_t>((size - 1) / 12, 256);
  bool finite = true;
  for (size_t i = 0; i < num; ++i) {
    float xyz[3];
    std::memcpy(xyz, data + 1 + 12 * i, 12);
    const Eigen::Vector3f p(xyz[0], xyz[1], xyz[2]);
    finite = finite && p.allFinite();
    cloud.points_G.push_back(p);
  }
  repair::RepairConfig config;
  config.mode = (flags & 2) ? repair::RepairMode::kPaper : repair::RepairMode::kBest;
  if (flags & 4) config.up_hint = Eigen::Vector3d(0, 0, -1);
  repair::RepairSteps steps = repair::RepairSteps::For(config.mode);
  try {
    const repair::RepairResult result = repair::RepairWithSteps(cloud, config, steps);
    FUZZ_CHECK(finite);
    FUZZ_CHECK(result.cloud.size() >= cloud.size());
    FUZZ_CHECK(result.cloud.provenance.size() == result.cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) {
      FUZZ_CHECK(std::memcmp(result.cloud.points_G[i].data(), cloud.points_G[i].data(), 12) == 0);
    }
    for (size_t i = cloud.size(); i < result.cloud.size(); ++i)
      FUZZ_CHECK(result.cloud.points_G[i].allFinite());
  } catch (const std::invalid_argument&) {
    FUZZ_CHECK(!finite);
  }
  return 0;
}
