// SPDX-License-Identifier: BSD-3-Clause
// The record asked about whole lists of points: what share of them it sees
// free, which of them to drop as seen free or inside the claw, and where a
// point inside the claw leaves it. The repair's checks of what it adds
// (src/repair/evidence_stage.cpp, repairer.cpp) are made of these; they
// know nothing of the repair's settings.
//
// Private to the library (not installed: the public API is
// graspfill/evidence/): included as "evidence/point_list_queries.hpp".
//
// The points are in the caller's frame V (the repair's virtual frame);
// T_in_V maps them into the record's frame (G). Only the claw's queries
// read V itself: its z axis is the object's axis. Pure and single-threaded.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <vector>

#include "graspfill/evidence/visibility_record.hpp"
#include "graspfill/types.hpp"

namespace graspfill::evidence {

/// Share of `points_V` the record sees free (0 for an empty list), of
/// those not flagged in `uncounted` (one flag per point) if given.
double SeenFreeShare(const VisibilityRecord& record, const std::vector<Eigen::Vector3f>& points_V,
                     const Eigen::Isometry3f& T_in_V, const std::vector<char>* uncounted = nullptr);

/// One flag per point of `points_V`: whether the record sees it free.
std::vector<char> SeenFreeFlags(const VisibilityRecord& record, const std::vector<Eigen::Vector3f>& points_V,
                                const Eigen::Isometry3f& T_in_V);
/// Removes the points the record sees free; returns how many. Only
/// those above `above_z_V` are tested (the others passed before).
int DropSeenFree(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                 std::vector<Eigen::Vector3f>* points_V,
                 float above_z_V = -std::numeric_limits<float>::infinity());

/// Moves each point inside the record's claw to where the ray from it
/// towards V's axis leaves the claw: a fill that bulged into a finger lands
/// on the finger's face, where the object touches it. Returns how many.
int PushOutOfClaw(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                  std::vector<Eigen::Vector3f>* points_V);

/// Removes the points inside the record's claw; returns how many. Only
/// those above `above_z_V` are tested (the others passed before).
int DropInsideClaw(const VisibilityRecord& record, const Eigen::Isometry3f& T_in_V,
                   std::vector<Eigen::Vector3f>* points_V,
                   float above_z_V = -std::numeric_limits<float>::infinity());

/// Share of the observed points of `cloud_G` (every point when it has no
/// provenance) the record sees free, asked of every k-th point,
/// k = max(1, n / max_tested) (every point for max_tested 0); 0 when
/// none is asked. A record of this
/// cloud sees almost none of them free.
double ObservedSeenFreeShare(const VisibilityRecord& record, const ObjectCloud& cloud_G, size_t max_tested);

}  // namespace graspfill::evidence
