// SPDX-License-Identifier: BSD-3-Clause
// The planner's safe bound (graspfill::SafeBound, types.hpp) from what the
// camera saw: a voxel of the workspace box is in the bound unless some key
// frame saw all of it free (its centre free by the margin plus its half
// diagonal), so the object, its unseen top and whatever hid behind the claw
// are always inside; a planner that keeps clear of every set voxel cannot
// touch the object, whatever the repair guessed.
#pragma once

#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/types.hpp"

namespace graspfill::evidence {

struct SafeBoundConfig {
  /// Voxel edge [m]: 5 mm keeps the default workspace at 40 x 40 x 60
  /// voxels, 12 KB as a bit set.
  double voxel_m{0.005};
  /// Throws std::invalid_argument unless 0.5 mm <= voxel_m <= 10 cm.
  void Validate() const;
};

/// The bound over the record's workspace box. An empty record (nothing
/// seen) gives the whole box. The record's own bound when it keeps one at
/// this voxel (the same bits: it was carved by the same key frames).
SafeBound ComputeSafeBound(const VisibilityRecord& record, const SafeBoundConfig& config = {});

/// Every voxel of `box` set: nothing carved yet.
SafeBound WholeBox(const fusion::WorkspaceBox& box, const SafeBoundConfig& config);

/// Clears the voxels of `bound` (over the record's workspace box) that
/// key frames first_key_frame.. of `record` see free.
void CarveSafeBound(const VisibilityRecord& record, size_t first_key_frame, SafeBound* bound);

}  // namespace graspfill::evidence
