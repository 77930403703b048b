// A fused-like object cloud with holes for the repair tests of rt/module:
// the paper's protocol cylinder (top cut off, three claw holes), every point
// observed, stamped like a cloud from Pipeline::ExtractCloud.
#pragma once

#include <cstdint>

#include "graspfill/synth/paper_protocol.hpp"
#include "graspfill/types.hpp"

namespace graspfill::rt::testing {

/// 15k points keep a repair around a tenth of a second.
inline ObjectCloud MakeProtocolObjectCloud(int64_t seq, int num_points = 15000) {
  synth::PaperProtocolConfig config;
  config.shape = synth::Shape::kCylinder;
  config.num_points = num_points;
  const synth::PaperProtocolCloud protocol = synth::MakePaperProtocolCloud(config);
  ObjectCloud cloud;
  cloud.seq = seq;
  cloud.utime = 1700000000000000 + seq;
  cloud.points_G = protocol.holey;
  cloud.provenance.assign(cloud.points_G.size(), Provenance::kObserved);
  cloud.timings = {{"extract", 2.5}};
  return cloud;
}

}  // namespace graspfill::rt::testing
