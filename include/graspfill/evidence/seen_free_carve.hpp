// SPDX-License-Identifier: BSD-3-Clause
// The fused cloud ends where the object ends: observed points that the
// camera saw through are removed at extraction.
//
// Where an edge is seen at a grazing angle, the truncation band of the
// views that graze it outweighs the views that pass beside it, and the
// TSDF's zero crossing runs a few millimetres past the edge (a phantom
// layer over rims, studs and thin parts). Some key frame's ray passed
// through each such point and measured a surface beyond it: the record's
// seen-free test (VisibilityRecord::SeenFree, its free margin and
// silhouette erosion) finds them. It is the test the repair's additions
// must pass, so observed and added points obey one rule.
#pragma once

#include <cstddef>

#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/types.hpp"

namespace graspfill::evidence {

/// Removes the points of `cloud` (G) of provenance kObserved that some key
/// frame of `record` saw free, keeping the order of the others (their
/// normals and provenance with them). Points of any other provenance are
/// kept. An empty record removes nothing. Allocates nothing. Returns the
/// number removed.
size_t CarveSeenFree(const VisibilityRecord& record, ObjectCloud* cloud);

}  // namespace graspfill::evidence
