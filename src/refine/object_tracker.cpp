// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/object_tracker.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace graspfill::refine {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
// Rotations are measured as the motion they give at this lever arm [m].
constexpr double kLeverM = 0.05;
// A last step within this many convergence thresholds ends the iterations
// as converged (matches switching at the gate's edge: a limit cycle).
constexpr double kSettledFactor = 4.0;

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("ObjectTrackingConfig: " + what);
}

double AngleOf(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

}  // namespace

void ObjectTrackingConfig::Validate() const {
  Require(warmup_frames >= 1, "warmup_frames must be >= 1");
  Require(min_model_points >= 10, "min_model_points must be >= 10");
  Require(model_refresh_frames >= 1, "model_refresh_frames must be >= 1");
  Require(cell_m > 0.0 && band_m > cell_m, "cell_m must be > 0 and band_m > cell_m");
  Require(max_points >= 10, "max_points must be >= 10");
  Require(normal_step_px >= 1, "normal_step_px must be >= 1");
  Require(normal_max_jump_m > 0.0, "normal_max_jump_m must be > 0");
  Require(max_normal_angle_deg > 0.0 && max_normal_angle_deg <= 180.0,
          "max_normal_angle_deg must be in (0, 180]");
  Require(gate_shrink > 0.0 && gate_shrink <= 1.0, "gate_shrink must be in (0, 1]");
  Require(final_gate_m > 0.0 && final_gate_m <= band_m, "final_gate_m must be in (0, band_m]");
  Require(max_iterations >= 1, "max_iterations must be >= 1");
  Require(huber_m > 0.0, "huber_m must be > 0");
  Require(damping >= 0.0 && damping < 1.0, "damping must be in [0, 1)");
  Require(min_constraint >= 0.0 && min_constraint < 1.0, "min_constraint must be in [0, 1)");
  Require(converged_m > 0.0 && converged_deg > 0.0, "convergence thresholds must be > 0");
  Require(min_matches >= 6, "min_matches must be >= 6");
  Require(max_rms_m > 0.0, "max_rms_m must be > 0");
  Require(min_step_m >= 0.0 && min_step_m < max_step_m, "min_step_m must be in [0, max_step_m)");
  Require(max_step_m > 0.0 && max_step_deg > 0.0 && max_total_m > 0.0 && max_total_deg > 0.0,
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
  const CameraIntrinsics& K = frame.intrinsics;
  if (K.width <= 0 || K.height <= 0 ||
      frame.depth_m.size() != static_cast<size_t>(K.width) * K.height) {
    return 0;
  }
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
  const float fx = static_cast<float>(K.fx), fy = static_cast<float>(K.fy);
  const float cx = static_cast<float>(K.cx), cy = static_cast<float>(K.cy);
  const float jump = static_cast<float>(config_.normal_max_jump_m);
  auto point = [&](int u, int v, float z) {
    return Eigen::Vector3f((u - cx) / fx * z, (v - cy) / fy * z, z);
  };
  const size_t cap = points_C_.capacity();
  size_t seen = 0;
  for (int v = step; v < K.height - step; ++v) {
    for (int u = step; u < W - step; ++u) {
      const float z = depth[v * W + u];
      if (!(z > 0.0f)) continue;
      if (seen++ % every != 0) continue;
      const float zl = depth[v * W + u - step], zr = depth[v * W + u + step];
      const float zu = depth[(v - step) * W + u], zd = depth[(v + step) * W + u];
      if (!(zl > 0.0f && zr > 0.0f && zu > 0.0f && zd > 0.0f)) continue;
      if (std::abs(zl - z) > jump || std::abs(zr - z) > jump || std::abs(zu - z) > jump ||
          std::abs(zd - z) > jump) {
        continue;
      }
      const Eigen::Vector3f p_C = point(u, v, z);
      Eigen::Vector3f n = (point(u + step, v, zr) - point(u - step, v, zl))
                              .cross(point(u, v + step, zd) - point(u, v - step, zu));
      const float len = n.norm();
      if (!(len > 0.0f)) continue;
      n /= len;
      if (n.dot(p_C) > 0.0f) n = -n;  // facing the camera
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
  // The object's pixels in G (the claw's frame: they do not move with S).
  const Eigen::Isometry3f T_G_C = T_C_G.inverse().cast<float>();
  const Eigen::Matrix3f R_G_C = T_G_C.linear();
  const float cos_min = static_cast<float>(std::cos(config_.max_normal_angle_deg * kDegToRad));
  const double huber = config_.huber_m;
  Eigen::Isometry3d S = S_G_;
  const Eigen::Vector3d centre_G = S * model_centre_.cast<double>();
  double gate = config_.band_m;
  bool converged = false, settled = false;
  bool underconstrained = false;  // at the last iteration
  int matches = 0;
  double rms = 0.0;
  int iterations = 0;
  for (int it = 0; it < config_.max_iterations; ++it) {
    const bool at_final = gate <= config_.final_gate_m * (1.0 + 1e-9);
    const Eigen::Isometry3f S_f = S.cast<float>();
    const Eigen::Isometry3f S_inv = S.inverse().cast<float>();
    const float gate2 = static_cast<float>(gate * gate);
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    matches = 0;
    double sum_r2 = 0.0;
    for (size_t i = 0; i < points_C_.size(); ++i) {
      const Eigen::Vector3f p_G = T_G_C * points_C_[i];
      const Eigen::Vector3f p_O = S_inv * p_G;
      const int idx = grid_.Nearest(p_O);
      if (idx < 0) continue;
      // The match in G, where the update moves it.
      const Eigen::Vector3f q_G = S_f * model_points_[idx];
      const Eigen::Vector3f m_G = S_f.linear() * model_normals_[idx];
      const Eigen::Vector3f d = p_G - q_G;
      if (d.squaredNorm() > gate2) continue;
      if ((R_G_C * normals_C_[i]).dot(m_G) < cos_min) continue;
      const double r = m_G.dot(d);
      const Eigen::Vector3d q = q_G.cast<double>() - centre_G;
      const Eigen::Vector3d m = m_G.cast<double>();
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = -q.cross(m) / kLeverM;  // rotation as a length at kLeverM
      J.tail<3>() = -m;
      const double w = std::abs(r) <= huber ? 1.0 : huber / std::abs(r);
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * r * J;
      sum_r2 += r * r;
      ++matches;
    }
    iterations = it + 1;
    rms = matches > 0 ? std::sqrt(sum_r2 / matches) : 0.0;
    if (matches < config_.min_matches) break;
    // Damped: a motion the matches leave free stays where it was.
    H.diagonal().array() += config_.damping * H.trace() / 6.0;
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    Eigen::Vector3d v;
    if (config_.estimate_rotation) {
      const Eigen::Matrix<double, 6, 1> xi = -H.ldlt().solve(g);
      w = xi.head<3>() / kLeverM;
      v = xi.tail<3>();
    } else {
      // Only along the directions the matches constrain: a face-on cuboid
      // (its other faces under the fingers) says nothing about the shift
      // along that face, and the model's edges would pull it there.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H.bottomRightCorner<3, 3>());
      const Eigen::Vector3d lambda = eig.eigenvalues();
      const Eigen::Matrix3d& E = eig.eigenvectors();
      v.setZero();
      underconstrained = false;
      for (int k = 0; k < 3; ++k) {
        if (lambda(k) > config_.min_constraint * lambda(2)) {
          v -= E.col(k) * (E.col(k).dot(g.tail<3>()) / lambda(k));
        } else {
          underconstrained = true;
        }
      }
    }
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    const double angle = w.norm();
    if (angle > 0.0) D.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    D.translation() = centre_G + v - D.linear() * centre_G;  // about the object's centre
    S = D * S;
    if (at_final && v.norm() < config_.converged_m && angle < config_.converged_deg * kDegToRad) {
      converged = true;
      break;
    }
    settled = at_final && v.norm() < kSettledFactor * config_.converged_m &&
              angle < kSettledFactor * config_.converged_deg * kDegToRad;
    gate = std::max(config_.final_gate_m, gate * config_.gate_shrink);
  }
  last_matches_ = matches;
  last_rms_m_ = rms;
  if (matches < config_.min_matches) {
    ++stats_.rejected_too_few_points;
    return TrackOutcome::kTooFewPoints;
  }
  if (!(converged || settled) || !(rms <= config_.max_rms_m)) {
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
  stats_.frames_underconstrained += underconstrained;
  stats_.iterations += iterations;
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
