// SPDX-License-Identifier: BSD-3-Clause
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
#include <limits>
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
  /// 4.29 vs 0.95 mm^2 with this deadband; docs/imperfect-robots.md) [m], [deg].
  double min_correction_m{0.0005};
  double min_correction_deg{0.5};
  /// Whether any registration can land within the deadband.
  bool has_deadband() const { return min_correction_m > 0.0 && min_correction_deg > 0.0; }
  /// The hand-eye correction predicts poses from this many accepted frames
  /// on; it is the median of the last `hand_eye_window` frames' corrections.
  int hand_eye_min_frames{5};
  int hand_eye_window{64};
  /// The clock offset between the robot's stamps and the camera's: a state
  /// stamped t that holds the pose of t + T makes the correction a turn by
  /// -T x the angular rate (in C), on top of the constant hand-eye part.
  /// On a steady turn the two cannot be told apart (the constant part
  /// absorbs both); when the rate varies, the slope of the corrections'
  /// rotation against the logged rate over the window is T. It is applied
  /// (the prediction moves the logged pose by T along the motion, and the
  /// hand-eye part is the median of the corrections without it) once at
  /// least `clock_min_frames` frames have a rate and its standard error is
  /// below `max_clock_stderr_s`, and stays applied while it is below twice
  /// that [s]. Until then, a frame beyond the jump bound only by a turn
  /// about the motion's axis (within rate x max_clock_offset_s) is not
  /// fused but enters the fits: it is where the offset shows most.
  int clock_min_frames{20};
  double max_clock_stderr_s{0.001};
  /// Estimates beyond this are not applied [s].
  double max_clock_offset_s{0.2};
  /// The sensor's depth is this many times the true one, as calibrated
  /// beforehand (e.g. a factor an earlier session reported): frames are
  /// divided by it from the first (depth_scale().applied starts here).
  /// 0.8..1.25.
  double known_depth_scale{1.0};
  /// The depth's scale is always estimated from the claw's size
  /// (PoseRefiner::CalibrateDepthScale); true: applied once confident (the
  /// pipeline divides the depth by it), false: only reported.
  bool apply_depth_scale{true};
  /// Frames farther apart than this give no rate [s].
  double max_rate_gap_s{0.1};

  /// Throws std::invalid_argument naming the bad field.
  void Validate() const;
};

/// The clock offset found from the corrections (RefineConfig::clock_*).
struct ClockOffsetEstimate {
  /// Known well enough to be applied (else offset_s is what the slope says
  /// but 0 is used).
  bool applied{false};
  /// What to add to the gripper states' stamps to put them on the camera's
  /// clock (the rig config's robot.clock_offset_s convention) [s].
  double offset_s{0.0};
  double stderr_s{0.0};  ///< its standard error (inf: not estimable) [s]
  int frames{0};         ///< frames with a rate in the window
};

/// The depth's scale error found from the claw's size in the depth
/// (ClawRegistration::EstimateDepthScale), over the session's fused frames.
struct DepthScaleEstimate {
  /// The sensor's depth is `factor` times the true one (1 + the median of
  /// the frames' errors); 1 until kDepthScaleMinFrames frames gave one.
  double factor{1.0};
  double stderr_{std::numeric_limits<double>::infinity()};  ///< of factor
  int frames{0};  ///< frames in the estimate (at most kDepthScaleWindow)
  /// What the depth is divided by before anything uses it (1: nothing).
  double applied{1.0};
  int changes{0};  ///< times `applied` changed
};

/// The depth scales a config may know (RefineConfig::known_depth_scale).
inline constexpr double kMinDepthScale = 0.8;
inline constexpr double kMaxDepthScale = 1.25;
/// Frames the depth-scale estimate takes its median over (the newest).
inline constexpr int kDepthScaleWindow = 256;
/// Fewer frames than this give no estimate: the claw's faces in view bias
/// a few frames' estimate by up to 0.3% on exact depth; over half of a
/// turn's 90 frames that averages out to within 0.2%.
inline constexpr int kDepthScaleMinFrames = 48;
/// The estimate replaces the applied factor when they differ by at least
/// this much and by kDepthScaleMinSigmas standard errors: on exact depth
/// the estimate stays within 0.2% (objects in the fingers and quantized
/// disparity bias it per grasp; docs/imperfect-robots.md), and a 0.2%
/// scale moves a surface 50 mm from the claw by 0.1 mm, below a voxel.
inline constexpr double kDepthScaleMinChange = 0.002;
inline constexpr double kDepthScaleMinSigmas = 4.0;

/// What refinement did with a frame.
enum class RefineOutcome {
  kRefined,       ///< registered: fuse at the refined pose
  kAtPrediction,  ///< registered within min_correction of the prediction: fuse at that
  kOff,           ///< refinement disabled: fuse at the logged pose
  kClawNotSeen,   ///< too few depth points near the predicted claw
  kNotConverged,  ///< the registration did not converge (or was degenerate)
  kJump,          ///< correction beyond max_correction / max_jump
};

/// "refined", "at_prediction", "off", "claw_not_seen", "not_converged", "jump".
const char* RefineOutcomeName(RefineOutcome outcome);
/// Whether the frame is fused (refined, at the prediction, or refinement off).
inline bool Fuses(RefineOutcome outcome) {
  return outcome == RefineOutcome::kRefined || outcome == RefineOutcome::kAtPrediction ||
         outcome == RefineOutcome::kOff;
}

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
  /// Rejected as jumps, but a turn along the motion that a clock offset not
  /// yet applied explains: in the clock and hand-eye fits, not fused.
  int64_t clock_only_samples{0};
  /// The depth's scale found so far (PoseRefiner::depth_scale()).
  DepthScaleEstimate depth_scale;

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

  /// The depth's scale from the frame the last Refine fused (call right
  /// after it; nothing when it was rejected or refinement is off), into the
  /// session's estimate. With apply_depth_scale, returns true when the
  /// factor to divide the depth by (depth_scale().applied) changed: the
  /// hand-eye estimate then starts anew, since it had absorbed the
  /// scale's shift along the ray.
  bool CalibrateDepthScale();

  /// The constant correction found so far: T_C_G ~= H * T_C_G_logged, in C
  /// (identity until hand_eye_min_frames frames were registered).
  Eigen::Isometry3d HandEyeCorrection() const;
  /// Frames in the hand-eye estimate (at most hand_eye_window).
  int hand_eye_samples() const { return static_cast<int>(samples_); }
  /// Where the claw was, on average, in C (the correction's lever) [m].
  Eigen::Vector3d claw_centre_C() const { return centre_mean_C_; }
  const RegistrationResult& last_registration() const { return last_; }
  const RefineStats& stats() const { return stats_; }
  const ClockOffsetEstimate& clock_offset() const { return clock_; }
  const DepthScaleEstimate& depth_scale() const { return stats_.depth_scale; }
  const RefineConfig& config() const { return config_; }

  /// Forgets the estimate and the statistics (keeps the claw).
  void Reset();

 private:
  // A correction as (rotation vector, motion of the claw centre) [rad], [m].
  // With the logged motion's rate at the frame: angular [rad/s] and of the
  // claw centre [m/s], in C (zero when has_rate is false).
  struct Sample {
    Eigen::Vector3d rotation{0, 0, 0};
    Eigen::Vector3d shift_at_claw{0, 0, 0};
    Eigen::Vector3d centre_C{0, 0, 0};
    Eigen::Vector3d angular_rate{0, 0, 0};
    Eigen::Vector3d claw_velocity{0, 0, 0};
    bool has_rate{false};
  };
  // The logged motion from the previous frame to this one, per second.
  struct Rate {
    Eigen::Isometry3d motion{Eigen::Isometry3d::Identity()};  // logged_k * logged_{k-1}^-1
    double dt_s{0.0};
    bool valid{false};
    Eigen::Vector3d Angular() const;
    Eigen::Vector3d VelocityAt(const Eigen::Vector3d& p_C) const;
  };
  void AddSample(const Eigen::Isometry3d& correction_C, const Eigen::Vector3d& centre_C, const Rate& rate);
  void UpdateEstimate();
  void UpdateClockOffset();
  void AddDepthScaleSample(double error);
  bool last_fused_{false};  // the last Refine registered a fused frame
  // Whether a registration's deviation from the prediction (`residual_C`,
  // moving the claw by `residual_m`) is a turn about the motion's axis that
  // a clock offset within max_clock_offset_s explains, the rest within the
  // jump bounds.
  bool ClockExplains(const Eigen::Isometry3d& residual_C, double residual_m, const Rate& rate) const;
  // The logged pose moved along its motion by the applied clock offset.
  Eigen::Isometry3d ClockShift(const Rate& rate) const;

  RefineConfig config_;
  ClawRegistration registration_;
  std::vector<Sample> window_;  // ring of hand_eye_window samples
  size_t next_{0};
  size_t samples_{0};
  std::vector<double> scratch_;  // for the medians
  Eigen::Isometry3d hand_eye_{Eigen::Isometry3d::Identity()};
  ClockOffsetEstimate clock_;
  std::vector<double> scale_errors_;  // ring of kDepthScaleWindow frames' errors
  size_t scale_next_{0};
  double shift_s_{0.0};  // applied: T_C_G(t) ~= H * pose logged at t + shift_s_
  Eigen::Isometry3d prev_logged_{Eigen::Isometry3d::Identity()};
  int64_t prev_utime_{-1};
  Rate previous_rate_;
  Eigen::Vector3d centre_mean_C_{0, 0, 0};
  RegistrationResult last_;
  RefineStats stats_;
};

}  // namespace graspfill::refine
