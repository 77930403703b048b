// SPDX-License-Identifier: BSD-3-Clause
// The mirror image against the evidence (evidence_config.hpp): lowered out
// of seen-free space when it caps the object too high, and its cap raised
// to where the rays carve it when it closes low. Pure and single-threaded.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "evidence_config.hpp"
#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/repair/repair_types.hpp"

namespace graspfill::repair {

/// Lowers a mirror image (`added_V`, made about the plane z = plane_z_V)
/// until at most `max_mirror_free_share` of it lies in seen-free space: the
/// plane drops by top_step_m up to max_plane_drop_m, each point by twice
/// the drop, and the points that fall below `floor_z_V` (the missing
/// surface's boundary: observed surface there) are dropped. Returns the
/// drop [m] (0 when the image already met the share), or NaN, leaving
/// `added_V` as it was, when no drop meets it (or no point is counted).
/// The points flagged in `uncounted` (one flag per point, kept in step),
/// if given, are lowered with the rest but not counted in the share.
double LowerMirrorOutOfFree(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                            const Eigen::Isometry3f& T_in_V, float floor_z_V, PointList* added_V,
                            std::vector<char>* uncounted = nullptr);

/// A mirror image's top: its highest point and its cap, the median height
/// of its top layer (the points within `layer_m` under the height that 1%
/// of the image exceeds, and those over it).
struct ImageTop {
  float highest_z_V{0.0f};
  float layer_from_z_V{0.0f};  ///< the top layer: z above this
  float cap_z_V{0.0f};
  int layer_points{0};
};
ImageTop TopOfImage(const PointList& image_V, double layer_m);

/// Raises the image's cap from `top.cap_z_V` to `cap_z_V`: its top
/// 2 x top_band_m are stretched, so that its walls rise with the cap.
/// Returns the height [m, V] above which points moved.
float StretchImageTop(const ImageTop& top, float cap_z_V, const EvidenceConfig& config, PointList* image_V);

/// How far the image's cap can rise before the rays carve it: the highest
/// lift (steps of top_step_m) at which at most max_cap_free_share of the
/// top layer is seen free, less carve_onset_m, at least 0. NaN when the
/// test cannot tell: fewer than min_cap_points in the layer, or no lift up
/// to max_mirror_lift_m carved.
double MirrorLiftFromCarving(const evidence::VisibilityRecord& record, const EvidenceConfig& config,
                             const Eigen::Isometry3f& T_in_V, const ImageTop& top, const PointList& image_V);

}  // namespace graspfill::repair
