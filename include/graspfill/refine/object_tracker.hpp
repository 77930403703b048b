// SPDX-License-Identifier: BSD-3-Clause
// Frame-to-model tracking of the object in the grasp: what the claw
// registration cannot fix, the object slipping in the fingers (it moves in
// G while the claw does not).
//
// The model is the surface fused so far (points and outward normals,
// extracted from the TSDF every few frames) in the object's frame O' = G as
// the object was first seen; the tracker keeps the object's pose in G,
// S_G (p_G = S_G * p_O'; the identity until it slips). Per frame, the
// masked object pixels (claw cut out, cropped to the workspace) are
// subsampled, given normals from their neighbours, and aligned to the model
// by point-to-plane ICP starting from the last accepted S_G (a slip is
// slow: a few mm over a few frames), with a closest-model-point lookup
// table built with the model. Matches need agreeing normals and are
// Huber-weighted; by default only the object's shift is estimated (a turn
// about an axis the shape leaves free, a cylinder's or a sphere's, is not
// observable), and the step is damped, so that motions the matches do not
// constrain stay where they were. An estimate within a deadband of the
// accepted pose leaves it. The caller then fuses the frame at
// T_C_G * S_G, so the volume stays in the object's frame.
//
// A frame whose alignment does not converge, has too few matches, or moves
// the object by more than a bound from the last accepted pose (or in all
// from where it was first seen) is rejected: counted with its reason and
// not fused.
//
// Pure and single-threaded; Track allocates nothing once its buffers have
// grown (SetModel reserves them and reuses its own).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/refine/closest_point_grid.hpp"
#include "graspfill/types.hpp"

namespace graspfill::refine {

struct ObjectTrackingConfig {
  /// Off by default: frames are fused at T_C_G (`replay --track-object`
  /// turns it on).
  bool enabled{false};
  /// Estimate the object's turn too, not only its shift. Off: a slip in
  /// the fingers is a slide, and a turn about an axis the shape leaves free
  /// (a cylinder's, a sphere's) is not observable: with it on, the model's
  /// growing edge turned a cylinder by 11 deg over a 90-frame recording.
  bool estimate_rotation{false};
  /// Tracking starts once this many frames have been fused (and the model
  /// extracted from them has `min_model_points`): 10 frames see 40 deg of
  /// a 3 s turn. From 3 (12 deg) a cuboid in the parallel claw, one face
  /// and the bottom in view, drifted 4.5 mm sideways in the first frames.
  /// A slip within the warm-up is not followed.
  int warmup_frames{10};
  int min_model_points{1500};
  /// The model is re-extracted from the volume after this many more fused
  /// frames (an extraction costs tens of ms).
  int model_refresh_frames{6};
  /// The lookup table: cell, and how far from the surface it answers [m].
  double cell_m{0.0015};
  double band_m{0.0045};
  /// At most this many object pixels per frame (an even subsample).
  int max_points{1500};
  /// Pixel normals from the neighbours this many pixels away; a neighbour
  /// farther in depth than `normal_max_jump_m` makes none [px], [m].
  int normal_step_px{2};
  double normal_max_jump_m{0.006};
  /// A match needs its pixel normal within this angle of the model's [deg].
  double max_normal_angle_deg{45.0};
  /// Gate schedule: from band_m, shrinking by this factor per iteration
  /// down to `final_gate_m` [m].
  double gate_shrink{0.7};
  double final_gate_m{0.002};
  int max_iterations{20};
  /// Huber threshold of the point-to-plane residuals [m].
  double huber_m{0.001};
  /// Damping of the normal equations, as a share of their mean diagonal:
  /// motions the matches do not constrain stay put.
  double damping{1e-3};
  /// Shift only: a direction whose constraint (eigenvalue of the normal
  /// equations) is below this share of the strongest one is not estimated
  /// (it keeps the accepted pose's value).
  double min_constraint{0.05};
  /// Converged when a step at the final gate moves the object less than
  /// these (at 5 cm for the rotation) [m], [deg].
  double converged_m{2e-5};
  double converged_deg{0.01};
  /// Fewer matches at the final gate: the object is not seen well enough.
  int min_matches{200};
  /// RMS point-to-plane residual above this: not converged [m].
  double max_rms_m{0.0015};
  /// Deadband: an estimate within this of the accepted pose (at the
  /// object's centre) leaves it as it is, and the frame is fused there.
  /// Without a slip the estimate wanders by up to ~0.9 mm over a turn (the
  /// model's rounded edges pull it; docs/imperfect-robots.md), which
  /// fused as is cost the still cylinder 0.2 mm of p95 [m].
  double min_step_m{0.001};
  /// A frame whose object pose moved more than this from the last accepted
  /// one (at the object's centre), or more than max_total_* from where it
  /// was first seen, is rejected [m], [deg].
  double max_step_m{0.004};
  double max_step_deg{3.0};
  double max_total_m{0.025};
  double max_total_deg{15.0};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

enum class TrackOutcome {
  kTracked,       ///< aligned: fuse at T_C_G * S_G
  kNoModel,       ///< no model yet (warm-up): fuse at T_C_G * S_G (identity)
  kTooFewPoints,  ///< too few object pixels or matches
  kNotConverged,  ///< no convergence, or the residual too high
  kJump,          ///< beyond max_step / max_total
};

struct TrackStats {
  int64_t frames_tracked{0};
  int64_t frames_no_model{0};
  int64_t rejected_too_few_points{0};
  int64_t rejected_not_converged{0};
  int64_t rejected_jump{0};
  int64_t model_updates{0};
  int64_t pose_updates{0};  ///< tracked frames that moved the pose (beyond min_step_m)
  /// Tracked frames whose matches left a direction of the shift below
  /// min_constraint (not estimated: a slide that way is not followed).
  int64_t frames_underconstrained{0};
  int64_t iterations{0};  ///< over the tracked frames
  int64_t matches{0};     ///< over the tracked frames
  double rms_sum_m{0.0};  ///< over the tracked frames
  /// The largest difference of a tracked frame's estimate from the accepted
  /// pose (at the object's centre) [m].
  double max_step_m{0.0};

  int64_t rejected() const { return rejected_too_few_points + rejected_not_converged + rejected_jump; }
};

class ObjectTracker {
 public:
  /// Throws std::invalid_argument on a bad config.
  explicit ObjectTracker(const ObjectTrackingConfig& config = {});

  /// Replaces the model (points and outward unit normals in the object's
  /// frame) and rebuilds the lookup table, reusing its memory.
  void SetModel(const std::vector<Eigen::Vector3f>& points_O, const std::vector<Eigen::Vector3f>& normals_O);
  bool has_model() const;
  size_t model_points() const { return model_points_.size(); }

  /// Aligns the object pixels of `object_frame` (everything not the object
  /// already 0: cropped and masked) taken with the gripper at `T_C_G`.
  /// On kTracked the pose S_G() is updated; otherwise it stays.
  TrackOutcome Track(const DepthFrame& object_frame, const Eigen::Isometry3d& T_C_G);

  /// The object's pose in G: p_G = S_G * p_O (identity until it moved).
  const Eigen::Isometry3d& S_G() const { return S_G_; }
  /// Camera pose for fusing into the object's frame: T_C_G * S_G.
  Eigen::Isometry3d T_C_O(const Eigen::Isometry3d& T_C_G) const { return T_C_G * S_G_; }
  int last_matches() const { return last_matches_; }
  double last_rms_m() const { return last_rms_m_; }
  const TrackStats& stats() const { return stats_; }
  const ObjectTrackingConfig& config() const { return config_; }

  /// Forgets the model, the pose and the statistics (a new object).
  void Reset();

 private:
  int CollectPoints(const DepthFrame& frame);

  ObjectTrackingConfig config_;
  std::vector<Eigen::Vector3f> model_points_;
  std::vector<Eigen::Vector3f> model_normals_;
  Eigen::Vector3f model_centre_{0, 0, 0};
  ClosestPointGrid grid_;                  // the model's closest points within band_m
  std::vector<Eigen::Vector3f> points_C_;  // reused per frame
  std::vector<Eigen::Vector3f> normals_C_;
  Eigen::Isometry3d S_G_{Eigen::Isometry3d::Identity()};
  int last_matches_{0};
  double last_rms_m_{0.0};
  TrackStats stats_;
};

}  // namespace graspfill::refine
