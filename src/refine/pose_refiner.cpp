// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/pose_refiner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "graspfill/core/require.hpp"

namespace graspfill::refine {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d FromRotationVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// How far `D` (a motion of C) moves a point at `centre_C` [m], and its angle [deg].
void MotionAt(const Eigen::Isometry3d& D, const Eigen::Vector3d& centre_C, double* m, double* deg) {
  *m = (D * centre_C - centre_C).norm();
  *deg = Eigen::AngleAxisd(D.linear()).angle() * kRadToDeg;
}

}  // namespace

void RefineConfig::Validate() const {
  registration.Validate();
  Require("RefineConfig", search_gate_m > 0.0 && tracking_gate_m > 0.0, "gates must be > 0");
  Require("RefineConfig", max_correction_m > 0.0 && max_correction_deg > 0.0, "max_correction must be > 0");
  Require("RefineConfig", max_jump_m > 0.0 && max_jump_deg > 0.0, "max_jump must be > 0");
  Require("RefineConfig", min_correction_m >= 0.0 && min_correction_deg >= 0.0,
          "min_correction must be >= 0");
  Require("RefineConfig", hand_eye_min_frames >= 1, "hand_eye_min_frames must be >= 1");
  Require("RefineConfig", hand_eye_window >= hand_eye_min_frames,
          "hand_eye_window must be >= hand_eye_min_frames");
  Require("RefineConfig", clock_min_frames >= 3, "clock_min_frames must be >= 3");
  Require("RefineConfig", known_depth_scale >= kMinDepthScale && known_depth_scale <= kMaxDepthScale,
          "known_depth_scale must be in [0.8, 1.25]");
  Require("RefineConfig", max_clock_stderr_s >= 0.0 && max_clock_offset_s >= 0.0 && max_rate_gap_s > 0.0,
          "clock bounds must be >= 0 and max_rate_gap_s > 0");
}

const char* RefineOutcomeName(RefineOutcome outcome) {
  switch (outcome) {
    case RefineOutcome::kRefined:
      return "refined";
    case RefineOutcome::kAtPrediction:
      return "at_prediction";
    case RefineOutcome::kOff:
      return "off";
    case RefineOutcome::kClawNotSeen:
      return "claw_not_seen";
    case RefineOutcome::kNotConverged:
      return "not_converged";
    case RefineOutcome::kJump:
      return "jump";
  }
  return "unknown";
}

PoseRefiner::PoseRefiner(const RefineConfig& config)
    : config_(config), registration_((config.Validate(), config.registration)) {
  window_.resize(static_cast<size_t>(config_.hand_eye_window));
  scratch_.reserve(std::max(window_.size(), static_cast<size_t>(kDepthScaleWindow)));
  scale_errors_.reserve(kDepthScaleWindow);
  stats_.depth_scale.applied = config_.known_depth_scale;
}

void PoseRefiner::SetClaw(const TriangleMesh& claw_G) { registration_.SetClaw(claw_G); }

void PoseRefiner::Reset() {
  next_ = 0;
  samples_ = 0;
  hand_eye_.setIdentity();
  clock_ = ClockOffsetEstimate{};
  scale_errors_.clear();
  scale_next_ = 0;
  last_fused_ = false;
  shift_s_ = 0.0;
  prev_utime_ = -1;
  previous_rate_ = Rate{};
  centre_mean_C_.setZero();
  last_ = RegistrationResult{};
  stats_ = RefineStats{};
  stats_.depth_scale.applied = config_.known_depth_scale;
}

Eigen::Isometry3d PoseRefiner::HandEyeCorrection() const {
  return static_cast<int>(samples_) >= config_.hand_eye_min_frames ? hand_eye_
                                                                   : Eigen::Isometry3d::Identity();
}

Eigen::Vector3d PoseRefiner::Rate::Angular() const {
  return valid ? Eigen::Vector3d(RotationVector(motion.linear()) / dt_s) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d PoseRefiner::Rate::VelocityAt(const Eigen::Vector3d& p_C) const {
  return valid ? Eigen::Vector3d((motion * p_C - p_C) / dt_s) : Eigen::Vector3d::Zero();
}

bool PoseRefiner::ClockExplains(const Eigen::Isometry3d& residual_C, double residual_m,
                                const Rate& rate) const {
  if (!rate.valid || residual_m > config_.max_jump_m) return false;
  const Eigen::Vector3d omega = rate.Angular();
  const double omega_norm = omega.norm();
  if (!(omega_norm > 0.0)) return false;
  const Eigen::Vector3d r = RotationVector(residual_C.linear());
  const double along = r.dot(omega) / omega_norm;
  const double across_deg = (r - along * omega / omega_norm).norm() * kRadToDeg;
  return across_deg <= config_.max_jump_deg && std::abs(along) <= omega_norm * config_.max_clock_offset_s;
}

Eigen::Isometry3d PoseRefiner::ClockShift(const Rate& rate) const {
  Eigen::Isometry3d E = Eigen::Isometry3d::Identity();
  if (shift_s_ == 0.0 || !rate.valid) return E;
  // A turn by shift x the rate about the claw centre, which moves by
  // shift x its velocity.
  const Eigen::Vector3d& c = centre_mean_C_;
  E.linear() = FromRotationVector(shift_s_ * rate.Angular());
  E.translation() = c + shift_s_ * rate.VelocityAt(c) - E.linear() * c;
  return E;
}

void PoseRefiner::AddSample(const Eigen::Isometry3d& correction_C, const Eigen::Vector3d& centre_C,
                            const Rate& rate) {
  Sample& s = window_[next_];
  s.rotation = RotationVector(correction_C.linear());
  s.shift_at_claw = correction_C * centre_C - centre_C;
  s.centre_C = centre_C;
  s.has_rate = rate.valid;
  s.angular_rate = rate.Angular();
  s.claw_velocity = rate.VelocityAt(centre_C);
  next_ = (next_ + 1) % window_.size();
  samples_ = std::min(samples_ + 1, window_.size());
  UpdateEstimate();
}

// Component-wise medians of the rotation and of the claw's shift (the shift
// at the claw, not at the camera's origin, so that the two do not trade
// off across samples through the 0.5 m lever), recombined about the mean
// claw centre.
void PoseRefiner::UpdateEstimate() {
  UpdateClockOffset();
  auto median = [&](auto get) {
    scratch_.clear();
    for (size_t i = 0; i < samples_; ++i) scratch_.push_back(get(window_[i]));
    const size_t mid = scratch_.size() / 2;
    std::nth_element(scratch_.begin(), scratch_.begin() + mid, scratch_.end());
    double m = scratch_[mid];
    if (scratch_.size() % 2 == 0) {
      m = 0.5 * (m + *std::max_element(scratch_.begin(), scratch_.begin() + mid));
    }
    return m;
  };
  Eigen::Vector3d w, shift;
  // Without the clock offset's part: that varies with the motion's rate.
  const double t = shift_s_;
  for (int k = 0; k < 3; ++k) {
    w[k] = median([k, t](const Sample& s) { return s.rotation[k] - t * s.angular_rate[k]; });
    shift[k] = median([k, t](const Sample& s) { return s.shift_at_claw[k] - t * s.claw_velocity[k]; });
  }
  centre_mean_C_.setZero();
  for (size_t i = 0; i < samples_; ++i) centre_mean_C_ += window_[i].centre_C;
  centre_mean_C_ /= static_cast<double>(samples_);
  hand_eye_.linear() = FromRotationVector(w);
  hand_eye_.translation() = centre_mean_C_ + shift - hand_eye_.linear() * centre_mean_C_;
}

// Least squares over the window's frames with a rate: rotation = a +
// shift x angular rate (componentwise a, one shift), so shift is the slope
// of the corrections against the rate about their means; its standard
// error follows from the residuals and the rate's spread, which a steady
// turn does not have.
void PoseRefiner::UpdateClockOffset() {
  Eigen::Vector3d mean_rate(0, 0, 0), mean_rotation(0, 0, 0);
  int n = 0;
  for (size_t i = 0; i < samples_; ++i) {
    if (!window_[i].has_rate) continue;
    mean_rate += window_[i].angular_rate;
    mean_rotation += window_[i].rotation;
    ++n;
  }
  clock_ = ClockOffsetEstimate{};
  clock_.frames = n;
  clock_.stderr_s = std::numeric_limits<double>::infinity();
  const bool was_applied = shift_s_ != 0.0;
  shift_s_ = 0.0;
  if (n < config_.clock_min_frames) return;
  mean_rate /= n;
  mean_rotation /= n;
  double spread = 0.0, cross = 0.0;
  for (size_t i = 0; i < samples_; ++i) {
    if (!window_[i].has_rate) continue;
    const Eigen::Vector3d dw = window_[i].angular_rate - mean_rate;
    spread += dw.squaredNorm();
    cross += dw.dot(window_[i].rotation - mean_rotation);
  }
  if (!(spread > 0.0)) return;
  const double slope = cross / spread;
  double residual = 0.0;
  for (size_t i = 0; i < samples_; ++i) {
    if (!window_[i].has_rate) continue;
    residual +=
        (window_[i].rotation - mean_rotation - slope * (window_[i].angular_rate - mean_rate)).squaredNorm();
  }
  clock_.offset_s = -slope;  // the stamps run behind by what the pose leads
  clock_.stderr_s = std::sqrt(residual / (3.0 * n - 4.0) / spread);
  // Once applied, it stays so while its standard error is under twice the
  // bound: dropping it for a frame moves the prediction by the whole offset.
  const double stderr_bound = (was_applied ? 2.0 : 1.0) * config_.max_clock_stderr_s;
  clock_.applied = clock_.stderr_s <= stderr_bound && std::abs(slope) <= config_.max_clock_offset_s;
  if (clock_.applied) shift_s_ = slope;
}

// The median of the window's errors (robust to a frame whose matches
// took the object for the claw), its standard error from their median
// absolute deviation (1.4826 MAD estimates the spread of normal errors,
// and a median's error is 1.2533 that of a mean).
void PoseRefiner::AddDepthScaleSample(double error) {
  if (scale_errors_.size() < static_cast<size_t>(kDepthScaleWindow)) {
    scale_errors_.push_back(error);
  } else {
    scale_errors_[scale_next_] = error;
  }
  scale_next_ = (scale_next_ + 1) % kDepthScaleWindow;
  stats_.depth_scale.frames = static_cast<int>(scale_errors_.size());
  if (stats_.depth_scale.frames < kDepthScaleMinFrames) return;
  scratch_.assign(scale_errors_.begin(), scale_errors_.end());
  const size_t mid = scratch_.size() / 2;
  std::nth_element(scratch_.begin(), scratch_.begin() + mid, scratch_.end());
  const double median = scratch_[mid];
  for (double& e : scratch_) e = std::abs(e - median);
  std::nth_element(scratch_.begin(), scratch_.begin() + mid, scratch_.end());
  const double mad = scratch_[mid];
  stats_.depth_scale.factor = 1.0 + median;
  stats_.depth_scale.stderr_ = 1.2533 * 1.4826 * mad / std::sqrt(static_cast<double>(scratch_.size()));
}

bool PoseRefiner::CalibrateDepthScale() {
  if (!last_fused_) return false;
  last_fused_ = false;
  DepthScaleSample sample;
  if (!registration_.EstimateDepthScale(last_, &sample)) return false;
  // The frame was divided by `applied` already: the sensor's error is both.
  AddDepthScaleSample(stats_.depth_scale.applied * (1.0 + sample.error) - 1.0);
  if (!config_.apply_depth_scale || !std::isfinite(stats_.depth_scale.stderr_)) return false;
  const double change = std::abs(stats_.depth_scale.factor / stats_.depth_scale.applied - 1.0);
  if (change < kDepthScaleMinChange || change < kDepthScaleMinSigmas * stats_.depth_scale.stderr_)
    return false;
  stats_.depth_scale.applied = stats_.depth_scale.factor;
  ++stats_.depth_scale.changes;
  next_ = 0;
  samples_ = 0;
  hand_eye_.setIdentity();
  return true;
}

RefineOutcome PoseRefiner::Refine(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G_logged,
                                  Eigen::Isometry3d* T_C_G) {
  last_fused_ = false;
  if (!config_.enabled) {
    *T_C_G = T_C_G_logged;
    return RefineOutcome::kOff;
  }
  // The logged motion since the previous frame (for the clock offset).
  Rate rate;
  if (prev_utime_ >= 0) {
    rate.dt_s = 1e-6 * static_cast<double>(frame.utime - prev_utime_);
    rate.valid = rate.dt_s > 0.0 && rate.dt_s <= config_.max_rate_gap_s;
    rate.motion = T_C_G_logged * prev_logged_.inverse();
  }
  prev_logged_ = T_C_G_logged;
  prev_utime_ = frame.utime;
  // The fit takes the rate of the step before (k-2 -> k-1): this frame's
  // own state noise is in both its correction and its latest rate, and
  // would pull the slope (by ~0.5 ms on a 0.6 speed variation).
  const Rate fit_rate = previous_rate_;
  previous_rate_ = rate;
  const bool tracking = static_cast<int>(samples_) >= config_.hand_eye_min_frames;
  const Eigen::Isometry3d prediction = tracking ? hand_eye_ * ClockShift(rate) * T_C_G_logged : T_C_G_logged;
  last_ =
      registration_.Register(frame, prediction, tracking ? config_.tracking_gate_m : config_.search_gate_m);
  switch (last_.status) {
    case RegistrationStatus::kConverged:
      break;
    case RegistrationStatus::kTooFewPoints:
    case RegistrationStatus::kNoClaw:
      ++stats_.rejected_claw_not_seen;
      return RefineOutcome::kClawNotSeen;
    case RegistrationStatus::kNotConverged:
    case RegistrationStatus::kDegenerate:
      ++stats_.rejected_not_converged;
      return RefineOutcome::kNotConverged;
  }
  const Eigen::Isometry3d correction = last_.T_C_G * T_C_G_logged.inverse();
  double corr_m, corr_deg, res_m, res_deg;
  MotionAt(correction, last_.centroid_C, &corr_m, &corr_deg);
  MotionAt(last_.correction_C, last_.centroid_C, &res_m, &res_deg);
  const bool too_far = tracking
                           ? (res_m > config_.max_jump_m || res_deg > config_.max_jump_deg)
                           : (corr_m > config_.max_correction_m || corr_deg > config_.max_correction_deg);
  if (too_far) {
    // Beyond the bound along the motion's turn only, and the clock offset
    // not applied yet: what an unknown clock offset does at this rate. Not
    // fused, but the clock fit learns from it; without such frames the fit
    // sees only the slow part of a varying turn and underestimates the
    // offset (a sphere at -30 ms: -21 ms, half its frames lost).
    if (tracking && !clock_.applied && ClockExplains(last_.correction_C, res_m, rate)) {
      AddSample(correction, last_.centroid_C, fit_rate);
      ++stats_.clock_only_samples;
    }
    ++stats_.rejected_jump;
    return RefineOutcome::kJump;
  }
  AddSample(correction, last_.centroid_C, fit_rate);
  ++stats_.frames_refined;
  stats_.iterations += last_.iterations;
  stats_.matches += last_.matches;
  stats_.rms_sum_m += last_.rms_m;
  stats_.correction_sum_m += corr_m;
  stats_.correction_sum_deg += corr_deg;
  if (tracking) {
    ++stats_.frames_tracked;
    stats_.residual_sum_m += res_m;
    stats_.residual_sum_deg += res_deg;
    stats_.max_residual_m = std::max(stats_.max_residual_m, res_m);
  }
  // Before the hand-eye correction is known the prediction is the logged
  // pose, so a correction below the registration's precision leaves that.
  const double beyond_m = tracking ? res_m : corr_m, beyond_deg = tracking ? res_deg : corr_deg;
  const bool below_precision = beyond_m < config_.min_correction_m && beyond_deg < config_.min_correction_deg;
  if (below_precision) ++stats_.frames_at_prediction;
  *T_C_G = below_precision ? prediction : last_.T_C_G;
  last_fused_ = true;
  return below_precision ? RefineOutcome::kAtPrediction : RefineOutcome::kRefined;
}

}  // namespace graspfill::refine
