// SPDX-License-Identifier: BSD-3-Clause
// One colour and one name per provenance, shared by the PLY writer (its
// red/green/blue properties, for viewers that ignore `provenance`) and the
// pictures of `graspfill view`, so that both tell the same story.
#pragma once

#include <array>
#include <cstdint>

#include "graspfill/types.hpp"

namespace graspfill {

using Rgb8 = std::array<uint8_t, 3>;

/// The colour of a point of this provenance: observed blue-grey, surface
/// fill orange, symmetry fill green (apart in hue, so that they stay
/// apart when shaded, and readable by most colour-blind people).
constexpr Rgb8 ProvenanceColor(Provenance p) {
  switch (p) {
    case Provenance::kSurface:
      return {230, 120, 20};
    case Provenance::kSymmetry:
      return {40, 170, 80};
    case Provenance::kObserved:
      break;
  }
  return {95, 125, 175};
}

/// The legend's name of the provenance.
constexpr const char* ProvenanceLabel(Provenance p) {
  switch (p) {
    case Provenance::kSurface:
      return "surface fill";
    case Provenance::kSymmetry:
      return "symmetry fill";
    case Provenance::kObserved:
      break;
  }
  return "observed";
}

}  // namespace graspfill
