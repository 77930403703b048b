// SPDX-License-Identifier: BSD-3-Clause
// A fused-like object cloud with holes for the repair tests of rt/module:
// the paper's protocol cylinder (top cut off, three claw holes), every point
// observed, stamped like a cloud from Pipeline::ExtractCloud.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>

#include "graspfill/types.hpp"
#include "synth/paper_protocol.hpp"

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

/// The repair's contract on `repaired`: more points than `fused`, the
/// fused ones first and unchanged (observed), then only added ones
/// (surface or symmetry).
inline ::testing::AssertionResult FusedThenAdded(const ObjectCloud& fused, const ObjectCloud& repaired) {
  if (repaired.size() <= fused.size()) return ::testing::AssertionFailure() << "nothing added";
  if (repaired.provenance.size() != repaired.size()) {
    return ::testing::AssertionFailure() << "provenance not one per point";
  }
  for (size_t i = 0; i < fused.size(); ++i) {
    if (repaired.points_G[i] != fused.points_G[i] || repaired.provenance[i] != Provenance::kObserved) {
      return ::testing::AssertionFailure() << "fused point " << i << " changed";
    }
  }
  for (size_t i = fused.size(); i < repaired.size(); ++i) {
    const Provenance p = repaired.provenance[i];
    if (p != Provenance::kSurface && p != Provenance::kSymmetry) {
      return ::testing::AssertionFailure() << "added point " << i << " has provenance observed";
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace graspfill::rt::testing
