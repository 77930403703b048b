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
/// seen) gives the whole box.
SafeBound ComputeSafeBound(const VisibilityRecord& record, const SafeBoundConfig& config = {});

}  // namespace graspfill::evidence
