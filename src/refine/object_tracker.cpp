// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/object_tracker.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "depth_pixel_normals.hpp"
#include "gated_icp.hpp"
#include "graspfill/core/require.hpp"

namespace graspfill::refine {
namespace {

constexpr double kDegToRad = kIcpDegToRad;

double AngleOf(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// The tracker's ICP problem (gated_icp.hpp): the object's pixels, fixed in
// G, matched to the model posed in G by S; residuals and the step in G,
// about the object's centre. The step is damped, and by default a shift
// along the directions the matches constrain.
class TrackerProblem {
 public:
  TrackerProblem(const ObjectTrackingConfig& config, const ClosestPointGrid& grid,
                 const std::vector<Eigen::Vector3f>& model_points_O,
                 const std::vector<Eigen::Vector3f>& model_normals_O,
                 const std::vector<Eigen::Vector3f>& points_C, const std::vector<Eigen::Vector3f>& normals_C,
                 const Eigen::Isometry3d& T_C_G)
      : config_(config),
        grid_(grid),
        model_points_O_(model_points_O),
        model_normals_O_(model_normals_O),
        points_C_(points_C),
        normals_C_(normals_C),
        T_G_C_(T_C_G.inverse().cast<float>()),
        R_G_C_(T_G_C_.linear()) {}

  void SetPose(const Eigen::Isometry3d& S, double /*gate_m*/) {
    S_f_ = S.cast<float>();
    S_inv_ = S.inverse().cast<float>();
  }
  size_t size() const { return points_C_.size(); }
  bool Nearest(size_t i, Eigen::Vector3f* p_G, Eigen::Vector3f* q_G, Eigen::Vector3f* m_G) const {
    *p_G = T_G_C_ * points_C_[i];
    const Eigen::Vector3f p_O = S_inv_ * *p_G;
    const int idx = grid_.Nearest(p_O);
    if (idx < 0) return false;
    // The match in G, where the step moves it.
    *q_G = S_f_ * model_points_O_[idx];
    *m_G = S_f_.linear() * model_normals_O_[idx];
    return true;
  }
  Eigen::Vector3f Normal(size_t i) const { return R_G_C_ * normals_C_[i]; }
  void InStepFrame(const Eigen::Vector3f& q_G, const Eigen::Vector3f& m_G, Eigen::Vector3d* q,
                   Eigen::Vector3d* m) const {
    *q = q_G.cast<double>();
    *m = m_G.cast<double>();
  }
  void Matched(size_t /*i*/) {}
  bool Step(Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& g, Eigen::Vector3d* w,
            Eigen::Vector3d* v) {
    // Damped: a motion the matches leave free stays where it was.
    H.diagonal().array() += config_.damping * H.trace() / 6.0;
    if (config_.estimate_rotation) {
      SolveFullStep(H, g, w, v);
      return true;
    }
    // Only along the directions the matches constrain: a face-on cuboid
    // (its other faces under the fingers) says nothing about the shift
    // along that face, and the model's edges would pull it there.
    w->setZero();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H.bottomRightCorner<3, 3>());
    const Eigen::Vector3d lambda = eig.eigenvalues();
    const Eigen::Matrix3d& E = eig.eigenvectors();
    v->setZero();
    underconstrained_ = false;
    for (int k = 0; k < 3; ++k) {
      if (lambda(k) > config_.min_constraint * lambda(2)) {
        *v -= E.col(k) * (E.col(k).dot(g.tail<3>()) / lambda(k));
      } else {
        underconstrained_ = true;
      }
    }
    return true;
  }

  // A direction of the shift was left out at the last step.
  bool underconstrained() const { return underconstrained_; }

 private:
  const ObjectTrackingConfig& config_;
  const ClosestPointGrid& grid_;
  const std::vector<Eigen::Vector3f>& model_points_O_;
  const std::vector<Eigen::Vector3f>& model_normals_O_;
  const std::vector<Eigen::Vector3f>& points_C_;
  const std::vector<Eigen::Vector3f>& normals_C_;
  const Eigen::Isometry3f T_G_C_;  // the pixels do not move with S
  const Eigen::Matrix3f R_G_C_;
  Eigen::Isometry3f S_f_;
  Eigen::Isometry3f S_inv_;
  bool underconstrained_{false};
};

}  // namespace

void ObjectTrackingConfig::Validate() const {
  Require("ObjectTrackingConfig", warmup_frames >= 1, "warmup_frames must be >= 1");
  Require("ObjectTrackingConfig", min_model_points >= 10, "min_model_points must be >= 10");
  Require("ObjectTrackingConfig", model_refresh_frames >= 1, "model_refresh_frames must be >= 1");
  Require("ObjectTrackingConfig", cell_m > 0.0 && band_m > cell_m, "cell_m must be > 0 and band_m > cell_m");
  RequireSampledIcpFields(
      *this, [](bool ok, const std::string& what) { Require("ObjectTrackingConfig", ok, what); });
  Require("ObjectTrackingConfig", final_gate_m > 0.0 && final_gate_m <= band_m,
          "final_gate_m must be in (0, band_m]");
  Require("ObjectTrackingConfig", max_iterations >= 1, "max_iterations must be >= 1");
  Require("ObjectTrackingConfig", huber_m > 0.0, "huber_m must be > 0");
  Require("ObjectTrackingConfig", damping >= 0.0 && damping < 1.0, "damping must be in [0, 1)");
  Require("ObjectTrackingConfig", min_constraint >= 0.0 && min_constraint < 1.0,
          "min_constraint must be in [0, 1)");
  Require("ObjectTrackingConfig", converged_m > 0.0 && converged_deg > 0.0,
          "convergence thresholds must be > 0");
  Require("ObjectTrackingConfig", min_matches >= 6, "min_matches must be >= 6");
  Require("ObjectTrackingConfig", max_rms_m > 0.0, "max_rms_m must be > 0");
  Require("ObjectTrackingConfig", min_step_m >= 0.0 && min_step_m < max_step_m,
          "min_step_m must be in [0, max_step_m)");
  Require("ObjectTrackingConfig",
          max_step_m > 0.0 && max_step_deg > 0.0 && max_total_m > 0.0 && max_total_deg > 0.0,
          "the jump bounds must be > 0");
}

ObjectTracker::ObjectTracker(const ObjectTrackingConfig& config) : config_(config) {
  config_.Validate();
  // CollectPoints keeps at most max_points pixels.
  points_C_.reserve(static_cast<size_t>(config_.max_points));
  normals_C_.reserve(static_cast<size_t>(config_.max_points));
}

bool ObjectTracker::has_model() const {
  return static_cast<int>(model_points_.size()) >= config_.min_model_points;
}

void ObjectTracker::SetModel(const std::vector<Eigen::Vector3f>& points_O,
                             const std::vector<Eigen::Vector3f>& normals_O) {
  if (points_O.size() != normals_O.size()) {
    throw std::invalid_argument("ObjectTracker::SetModel: points and normals differ in count");
  }
  model_points_.clear();
  model_normals_.clear();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < points_O.size(); ++i) {
    const float len = normals_O[i].norm();
    if (!points_O[i].allFinite() || !(len > 0.0f)) continue;
    model_points_.push_back(points_O[i]);
    model_normals_.push_back(normals_O[i] / len);
    sum += points_O[i].cast<double>();
  }
  ++stats_.model_updates;
  if (model_points_.empty()) {
    grid_.Clear();
    return;
  }
  model_centre_ = (sum / static_cast<double>(model_points_.size())).cast<float>();
  grid_.Build(model_points_, 1, config_.cell_m, config_.band_m);
}

int ObjectTracker::CollectPoints(const DepthFrame& frame) {
  points_C_.clear();
  normals_C_.clear();
  if (!DepthPixelNormals::Fits(frame)) return 0;
  const CameraIntrinsics& K = frame.intrinsics;
  const int step = config_.normal_step_px;
  const int W = K.width;
  const float* depth = frame.depth_m.data();
  // Pass 1: how many object pixels; pass 2: every k-th of them (an even,
  // deterministic subsample) with a normal.
  size_t valid = 0;
  for (int v = step; v < K.height - step; ++v) {
    for (int u = step; u < W - step; ++u) valid += depth[v * W + u] > 0.0f;
  }
  if (valid == 0) return 0;
  const size_t every = std::max<size_t>(1, (valid + config_.max_points - 1) / config_.max_points);
  const DepthPixelNormals pixels(K, depth, step, config_.normal_max_jump_m);
  const size_t cap = points_C_.capacity();
  size_t seen = 0;
  for (int v = step; v < K.height - step; ++v) {
    for (int u = step; u < W - step; ++u) {
      const float z = depth[v * W + u];
      if (!(z > 0.0f)) continue;
      if (seen++ % every != 0) continue;
      const Eigen::Vector3f p_C = pixels.Point(u, v, z);
      Eigen::Vector3f n;
      if (!pixels.Normal(u, v, z, p_C, &n)) continue;
      if (points_C_.size() == cap) break;  // never reallocate in the frame path
      points_C_.push_back(p_C);
      normals_C_.push_back(n);
    }
  }
  return static_cast<int>(points_C_.size());
}

TrackOutcome ObjectTracker::Track(const DepthFrame& object_frame, const Eigen::Isometry3d& T_C_G) {
  last_matches_ = 0;
  last_rms_m_ = 0.0;
  if (!has_model()) {
    ++stats_.frames_no_model;
    return TrackOutcome::kNoModel;
  }
  if (CollectPoints(object_frame) < config_.min_matches) {
    ++stats_.rejected_too_few_points;
    return TrackOutcome::kTooFewPoints;
  }
  Eigen::Isometry3d S = S_G_;
  const Eigen::Vector3d centre_G = S * model_centre_.cast<double>();
  TrackerProblem problem(config_, grid_, model_points_, model_normals_, points_C_, normals_C_, T_C_G);
  const GatedIcpOutcome icp = RunGatedIcp(GatedIcpScheduleOf(config_, config_.band_m), centre_G, problem, &S);
  const int matches = icp.matches;
  const double rms = icp.rms_m;
  last_matches_ = matches;
  last_rms_m_ = rms;
  if (icp.end == GatedIcpEnd::kTooFewMatches) {
    ++stats_.rejected_too_few_points;
    return TrackOutcome::kTooFewPoints;
  }
  if (!(icp.end == GatedIcpEnd::kConverged || icp.settled) || !(rms <= config_.max_rms_m)) {
    ++stats_.rejected_not_converged;
    return TrackOutcome::kNotConverged;
  }
  S.linear() = Eigen::Quaterniond(S.linear()).normalized().toRotationMatrix();
  // Bounds at the object's centre: the step from the last accepted pose,
  // and the whole motion since the object was first seen.
  const Eigen::Vector3d c_O = model_centre_.cast<double>();
  const double step_m = (S * c_O - S_G_ * c_O).norm();
  const double step_rad = AngleOf(S_G_.linear().transpose() * S.linear());
  const double total_m = (S * c_O - c_O).norm();
  const double total_rad = AngleOf(S.linear());
  if (step_m > config_.max_step_m || step_rad > config_.max_step_deg * kDegToRad ||
      total_m > config_.max_total_m || total_rad > config_.max_total_deg * kDegToRad) {
    ++stats_.rejected_jump;
    return TrackOutcome::kJump;
  }
  // Within the deadband the accepted pose stays: the estimate's own
  // wander (bias from the model's rounded edges, noise) is not a slip.
  stats_.max_step_m = std::max(stats_.max_step_m, step_m);
  if (step_m >= config_.min_step_m) {
    S_G_ = S;
    ++stats_.pose_updates;
  }
  ++stats_.frames_tracked;
  stats_.frames_underconstrained += problem.underconstrained();
  stats_.iterations += icp.iterations;
  stats_.matches += matches;
  stats_.rms_sum_m += rms;
  return TrackOutcome::kTracked;
}

void ObjectTracker::Reset() {
  model_points_.clear();
  model_normals_.clear();
  grid_.Clear();
  S_G_ = Eigen::Isometry3d::Identity();
  last_matches_ = 0;
  last_rms_m_ = 0.0;
  stats_ = TrackStats{};
}

}  // namespace graspfill::refine
