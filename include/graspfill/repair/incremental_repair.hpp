// SPDX-License-Identifier: BSD-3-Clause
// The repair kept up to date between full repairs: while the robot turns
// the object the fused cloud changes a little from one update to the next,
// so an update keeps what the last full repair (the base) added where it
// still holds, and costs milliseconds instead of a full repair's
// 60-1,000 ms.
//
// An update: the fused points as extracted now, plus the base's added
// points except those the camera has since measured (a new fused point
// within a cell of them: the measurement wins) and those the record now
// sees free (never an added point in seen-free space). The holes and the
// safe bound are the base's (the bound only shrinks as frames come, so the
// base's is a superset: still safe).
//
// When a full repair is due (the documented rule, RebaseReason): no base,
// another grasp, more than max_new_surface_share of the fused points where
// the base's fused cloud had none (a hole came into view, a side turned
// round), or more than max_dropped_share of the base's added points gone.
// The update's output is still the best model until the full repair lands.
//
// Pure and single-threaded; NOT thread safe.
#pragma once

#include <cstdint>
#include <vector>

#include "graspfill/core/bit_grid.hpp"
#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/types.hpp"

namespace graspfill::repair {

struct IncrementalConfig {
  /// Cell of the change test [m]: a fused point is new when the base's
  /// fused cloud has no point in its cell or the 26 around it (3-6 mm: 2-4
  /// TSDF voxels, more than a fused surface moves as frames average in,
  /// less than a claw hole).
  float cell_m{0.003f};
  /// A full repair is due when more than this share of the fused points is
  /// new.
  double max_new_surface_share{0.05};
  /// ... or when more than this share of the base's added points has been
  /// dropped (measured since, or seen free).
  double max_dropped_share{0.25};
  /// ... or when the record has this many key frames more than the base's
  /// repair saw (new views carve the fills and fix the top's height; 0 =
  /// never).
  int max_new_key_frames{2};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// Why the next model should come from a full repair.
enum class RebaseReason : uint8_t {
  kNone = 0,      ///< the update holds
  kNoBase,        ///< nothing repaired yet (or after Reset)
  kOtherGrasp,    ///< the fused cloud is of another grasp than the base
  kNewSurface,    ///< too much fused surface the base did not have
  kAddedDropped,  ///< too many of the base's added points gone
  kNewEvidence,   ///< the record has enough new key frames
};

const char* RebaseReasonName(RebaseReason reason);

struct UpdateReport {
  RebaseReason rebase{RebaseReason::kNone};
  /// Share of the fused points new since the base.
  double new_surface_share{0.0};
  int added_kept{0};
  int dropped_measured{0};  ///< added points the camera has measured since
  int dropped_free{0};      ///< added points the record now sees free
  bool full_due() const { return rebase != RebaseReason::kNone; }
};

class IncrementalRepair {
 public:
  /// Throws std::invalid_argument on a bad config.
  explicit IncrementalRepair(const IncrementalConfig& config = {});

  /// Takes a full repair's output as the base: its observed points are the
  /// fused cloud it was made from, the rest what the repair added. Throws
  /// std::invalid_argument when the cloud's extent is too large for the
  /// change grid (leaving no base). `record`: what the repair was given
  /// (its key frames are counted; null = none).
  void Rebase(const ObjectCloud& repaired, const evidence::VisibilityRecord* record = nullptr);

  /// The fused cloud `fused` (all observed, as extracted) brought up to date
  /// with the base into `*out` (its buffers reused). With kNoBase or
  /// kOtherGrasp, `*out` is `fused` as it came (nothing to add from).
  UpdateReport Update(const ObjectCloud& fused, const evidence::VisibilityRecord* record, ObjectCloud* out);

  bool has_base() const { return has_base_; }
  /// Forgets the base.
  void Reset() { has_base_ = false; }

 private:
  IncrementalConfig config_;
  bool has_base_{false};
  int64_t base_grasp_id_{0};
  size_t base_key_frames_{0};
  ObjectCloud added_;  // the base's added points (positions, normals, provenance, confidence)
  std::vector<HoleSummary> holes_;
  SafeBound safe_bound_;
  Eigen::AlignedBox3f box_;  // the change grids' box: the base's bulk, widened
  BitGrid base_observed_;    // the base's fused points, dilated by a cell
  BitGrid fresh_;            // this update's new fused points, dilated
  std::vector<uint8_t> keep_;
};

}  // namespace graspfill::repair
