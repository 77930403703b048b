// The parts of a replayed cloud: the fused points (provenance observed) and
// the points the hole repair added after them.
#pragma once

#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::testing {

/// The points fused from depth frames, in order. Checks about the fusion use
/// these only, so that they pin the fusion and not the repair.
inline std::vector<Eigen::Vector3f> ObservedPoints(const ObjectCloud& cloud) {
  std::vector<Eigen::Vector3f> observed;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.provenance.empty() || cloud.provenance[i] == Provenance::kObserved) {
      observed.push_back(cloud.points_G[i]);
    }
  }
  return observed;
}

}  // namespace graspfill::testing
