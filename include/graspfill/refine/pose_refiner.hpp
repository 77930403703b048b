// Pose refinement for imperfect robots: corrects the logged gripper pose of
// every depth frame before the claw mask and the fusion use it.
//
// A real rig's logged T_C_G is off by a constant hand-eye error (a wrong
// T_C_B moves every pose the same way in the camera frame), by per-state
// noise (encoders, arm flex) and by what a clock offset between robot and
// camera does to a moving gripper. Per frame, the claw is registered to the
// depth (claw_registration.hpp); the constant part is estimated over the
// frames as the median of their corrections (so the noise averages out) and
// predicts the next frame's pose, from which the registration then only
// tracks the noise with a narrow gate. A frame is fused at its registered
// pose, or not at all: no claw in view, no convergence, or a correction
// beyond the bounds below is skipped and counted with its reason.
//
// Pure and single-threaded; Refine allocates nothing after SetClaw.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "graspfill/refine/claw_registration.hpp"
#include "graspfill/types.hpp"

namespace graspfill::refine {

struct RefineConfig {
  /// On by default; off, frames are fused at their logged poses
  /// (`replay --no-refine`, `live --no-refine`, rig config `refine.enabled`).
  bool enabled{true};
  ClawRegistrationConfig registration;
  /// First-iteration gate while the hand-eye correction is not known yet:
  /// what a few mm and about a degree of hand-eye error do at 0.5 m [m].
  double search_gate_m{0.025};
  /// The same once it is known (noise and clock effects only) [m].
  double tracking_gate_m{0.008};
  /// Before the hand-eye correction is known, a frame whose correction of
  /// the logged pose moves the claw more than this is rejected [m], [deg].
  double max_correction_m{0.03};
  double max_correction_deg{5.0};
  /// Once it is known, a frame whose registered pose is farther than this
  /// from the prediction (hand-eye correction * logged pose), at the claw,
  /// is rejected: a pose that jumped, or a wrong registration [m], [deg].
  double max_jump_m{0.005};
  double max_jump_deg{2.0};
  /// A registered pose within both of these of the prediction (the hand-eye
  /// correction times the logged pose; the logged pose before it is known),
  /// at the claw, is not used: the prediction is. On an exact recording the
  /// registration jitters by ~0.16 mm / 0.25 deg a frame, and that jitter,
  /// fused, cost the prism in the three-finger claw its claw holes (chamfer
  /// 4.29 vs 0.95 mm^2 with this deadband; README, Imperfect robots) [m], [deg].
  double min_correction_m{0.0005};
  double min_correction_deg{0.5};
  /// The hand-eye correction predicts poses from this many accepted frames
  /// on; it is the median of the last `hand_eye_window` frames' corrections.
  int hand_eye_min_frames{5};
  int hand_eye_window{64};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// What refinement did with a frame.
enum class RefineOutcome {
  kRefined,        ///< registered: fuse at the refined pose
  kOff,            ///< refinement disabled: fuse at the logged pose
  kClawNotSeen,    ///< too few depth points near the predicted claw
  kNotConverged,   ///< the registration did not converge (or was degenerate)
  kJump,           ///< correction beyond max_correction / max_jump
};

/// "refined", "off", "claw_not_seen", "not_converged", "jump".
const char* RefineOutcomeName(RefineOutcome outcome);

struct RefineStats {
  int64_t frames_refined{0};
  int64_t rejected_claw_not_seen{0};
  int64_t rejected_not_converged{0};
  int64_t rejected_jump{0};
  int64_t iterations{0};  ///< over the refined frames
  int64_t matches{0};     ///< claw points matched, over the refined frames
  double rms_sum_m{0.0};  ///< point-to-plane RMS, summed over refined frames
  /// Of the refined frames: how far the registered pose moved the claw from
  /// the logged pose [m], [deg]; of those refined once the hand-eye
  /// correction was known (`frames_tracked`), how far from the prediction
  /// (the per-frame part: noise, and what the constant part misses).
  double correction_sum_m{0.0};
  double correction_sum_deg{0.0};
  int64_t frames_tracked{0};
  int64_t frames_at_prediction{0};  ///< refined, correction below min_correction: fused at the prediction
  double residual_sum_m{0.0};
  double residual_sum_deg{0.0};
  double max_residual_m{0.0};

  int64_t rejected() const { return rejected_claw_not_seen + rejected_not_converged + rejected_jump; }
};

class PoseRefiner {
 public:
  /// Throws std::invalid_argument on a bad config.
  explicit PoseRefiner(const RefineConfig& config = {});

  /// The posed claw in G (setup time, see ClawRegistration::SetClaw).
  void SetClaw(const TriangleMesh& claw_G);

  /// Refines the logged pose of `frame` into `T_C_G` (the logged pose when
  /// refinement is off; untouched when the frame is rejected).
  RefineOutcome Refine(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G_logged,
                       Eigen::Isometry3d* T_C_G);

  /// The constant correction found so far: T_C_G ~= H * T_C_G_logged, in C
  /// (identity until hand_eye_min_frames frames were registered).
  Eigen::Isometry3d HandEyeCorrection() const;
  /// Frames in the hand-eye estimate (at most hand_eye_window).
  int hand_eye_samples() const { return static_cast<int>(samples_); }
  /// Where the claw was, on average, in C (the correction's lever) [m].
  Eigen::Vector3d claw_centre_C() const { return centre_mean_C_; }
  const RegistrationResult& last_registration() const { return last_; }
  const RefineStats& stats() const { return stats_; }
  const RefineConfig& config() const { return config_; }

  /// Forgets the estimate and the statistics (keeps the claw).
  void Reset();

 private:
  // A correction as (rotation vector, motion of the claw centre) [rad], [m].
  struct Sample {
    Eigen::Vector3d rotation{0, 0, 0};
    Eigen::Vector3d shift_at_claw{0, 0, 0};
    Eigen::Vector3d centre_C{0, 0, 0};
  };
  void AddSample(const Eigen::Isometry3d& correction_C, const Eigen::Vector3d& centre_C);
  void UpdateEstimate();

  RefineConfig config_;
  ClawRegistration registration_;
  std::vector<Sample> window_;  // ring of hand_eye_window samples
  size_t next_{0};
  size_t samples_{0};
  std::vector<double> scratch_;  // for the medians
  Eigen::Isometry3d hand_eye_{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d centre_mean_C_{0, 0, 0};
  RegistrationResult last_;
  RefineStats stats_;
};

}  // namespace graspfill::refine
