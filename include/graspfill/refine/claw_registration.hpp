// SPDX-License-Identifier: BSD-3-Clause
// Claw registration: aligns the posed claw model to the depth pixels near
// its predicted place in a frame (point-to-plane ICP, after Krainin et al.
// 2011, who tracked a robot's hand by aligning its model to the depth),
// giving a correction of the gripper pose T_C_G for that frame.
//
// The model is the posed claw surface in G, sampled every ~2 mm, with a
// closest-model-point lookup table over two voxel grids around it (a
// coarse one reaching 25 mm for the first search, a fine one reaching 6 mm
// for tracking), both built once per claw (setup time), so that one ICP
// iteration costs one table lookup per depth point. Depth points are
// matched to their nearest model point when it is within the iteration's
// gate and the two normals agree (the object's surface beside a finger
// faces it, the model's does not, so the object does not pull the claw);
// residuals are Huber-weighted. The update is a small rigid motion of the
// camera frame about the matched points' centroid (well conditioned where
// the claw is, 0.5 m from the camera).
//
// Pure and single-threaded; Register allocates nothing once its buffers
// have grown (they are reserved by SetClaw).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/refine/closest_point_grid.hpp"
#include "graspfill/types.hpp"

namespace graspfill::refine {

struct ClawRegistrationConfig {
  /// Spacing of the model's surface samples [m].
  double model_spacing_m{0.002};
  /// The fine lookup grid (cell, and how far from the surface it answers)
  /// and the coarse one, used while the gate is wider than the fine band [m].
  double fine_cell_m{0.0015};
  double fine_band_m{0.006};
  double coarse_cell_m{0.004};
  double coarse_band_m{0.026};
  /// At most this many depth points per frame (an even subsample of the
  /// pixels near the claw).
  int max_points{1500};
  /// Depth normals from the neighbours this many pixels away (a wider
  /// baseline than 1 px: sensor noise of ~1 mm over 1 mm pixels would turn
  /// them by ~45 deg).
  int normal_step_px{3};
  /// Neighbours whose depth differs from the centre's by more than this
  /// make no normal (a silhouette) [m].
  double normal_max_jump_m{0.01};
  /// A match needs its depth normal within this angle of the model's [deg].
  double max_normal_angle_deg{50.0};
  /// Gate schedule: the first iteration's gate is Register's argument, each
  /// next one this factor of it, down to `final_gate_m` [m].
  double gate_shrink{0.6};
  double final_gate_m{0.004};
  int max_iterations{20};
  /// Huber threshold of the point-to-plane residuals [m].
  double huber_m{0.0015};
  /// Converged when a step at the final gate moves the claw less than these.
  double converged_m{5e-5};
  double converged_deg{0.02};
  /// Fewer matched points than this at the final gate: the claw is not in
  /// view (or not where the pose says) [points].
  int min_matches{120};
  /// An RMS point-to-plane residual above this: not converged [m].
  double max_rms_m{0.0025};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

enum class RegistrationStatus {
  kConverged,
  kTooFewPoints,  ///< the claw is not in view, or the frame has no depth there
  kNotConverged,  ///< no convergence within max_iterations, or residual too high
  kDegenerate,    ///< the matched points do not constrain all six motions
  kNoClaw,        ///< SetClaw was not called (or the claw was empty)
};

/// "converged", "too_few_points", "not_converged", "degenerate", "no_claw".
const char* RegistrationStatusName(RegistrationStatus status);

/// One frame's depth-scale error: its depth is (1 + error) times the true
/// one, as the claw's size in the depth says (its place along the ray is
/// the hand-eye correction's to explain).
struct DepthScaleSample {
  double error{0.0};
  double stderr_{0.0};  ///< its standard error
  int matches{0};
};

struct RegistrationResult {
  RegistrationStatus status{RegistrationStatus::kNoClaw};
  /// T_C_G_registered = correction_C * T_C_G_initial.
  Eigen::Isometry3d correction_C{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d T_C_G{Eigen::Isometry3d::Identity()};  ///< registered pose
  int candidates{0};                                       ///< depth points near the predicted claw
  int matches{0};                                          ///< matched at the final gate
  int iterations{0};
  double rms_m{0.0};  ///< RMS point-to-plane residual of the matches
  /// Centroid of the matched depth points in C (where the claw is).
  Eigen::Vector3d centroid_C{0.0, 0.0, 0.0};
};

class ClawRegistration {
 public:
  explicit ClawRegistration(const ClawRegistrationConfig& config = {});

  /// Samples the posed claw surface (in G, triangles wound outwards) and
  /// builds the lookup grids. Setup-time work (tens of ms): call when the
  /// claw's opening changes.
  void SetClaw(const TriangleMesh& claw_G);
  bool has_claw() const { return !model_points_G_.empty(); }

  /// Registers the claw in `frame` starting from `T_C_G_initial`, matching
  /// points up to `initial_gate_m` away in the first iteration (the error
  /// the initial pose may have at the claw) [m].
  RegistrationResult Register(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G_initial,
                              double initial_gate_m);

  /// The depth's scale error in the frame `registered` came from (call
  /// right after that Register: it uses its depth points, and moves them):
  /// the claw's size in the depth against the model's. False when the
  /// registration did not converge or too few points matched.
  bool EstimateDepthScale(const RegistrationResult& registered, DepthScaleSample* sample);

  const ClawRegistrationConfig& config() const { return config_; }
  /// The model's surface samples and their outward unit normals, in G.
  const std::vector<Eigen::Vector3f>& model_points_G() const { return model_points_G_; }
  const std::vector<Eigen::Vector3f>& model_normals_G() const { return model_normals_G_; }

 private:
  // Depth points near the predicted claw (C), with normals facing the camera.
  int CollectCandidates(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G, double gate_m);

  ClawRegistrationConfig config_;
  std::vector<Eigen::Vector3f> model_points_G_;
  std::vector<Eigen::Vector3f> model_normals_G_;
  Eigen::AlignedBox3f model_box_G_;
  ClosestPointGrid fine_;  // the model's closest points, fine and coarse
  ClosestPointGrid coarse_;
  std::vector<Eigen::Vector3f> points_C_;  // reused per frame
  std::vector<Eigen::Vector3f> normals_C_;
};

}  // namespace graspfill::refine
