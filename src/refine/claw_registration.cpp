// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/claw_registration.hpp"

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
// Box corners nearer than this to the camera plane: no projection.
constexpr double kMinDepthM = 0.05;
// A step is measured at this lever arm for the rotation's share [m].
constexpr double kLeverM = 0.05;
// Smallest / largest eigenvalue of the normal equations (rotations about
// the centroid scaled by kLeverM) below this: the matches leave a motion
// unconstrained.
constexpr double kMinConditioning = 1e-5;
// A last step within this many convergence thresholds ends the iterations
// as converged.
constexpr double kSettledFactor = 4.0;

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("ClawRegistrationConfig: " + what);
}

// R2 low-discrepancy sequence (Roberts 2018): even, deterministic samples.
constexpr double kR2a = 0.7548776662466927;
constexpr double kR2b = 0.5698402909980532;

}  // namespace

void ClawRegistrationConfig::Validate() const {
  Require(model_spacing_m > 0.0, "model_spacing_m must be > 0");
  Require(fine_cell_m > 0.0 && coarse_cell_m > 0.0, "grid cells must be > 0");
  Require(fine_band_m > 0.0 && coarse_band_m >= fine_band_m,
          "bands must be > 0 and coarse_band_m >= fine_band_m");
  Require(max_points >= 10, "max_points must be >= 10");
  Require(normal_step_px >= 1, "normal_step_px must be >= 1");
  Require(normal_max_jump_m > 0.0, "normal_max_jump_m must be > 0");
  Require(max_normal_angle_deg > 0.0 && max_normal_angle_deg <= 180.0,
          "max_normal_angle_deg must be in (0, 180]");
  Require(gate_shrink > 0.0 && gate_shrink <= 1.0, "gate_shrink must be in (0, 1]");
  Require(final_gate_m > 0.0 && final_gate_m <= fine_band_m,
          "final_gate_m must be in (0, fine_band_m]");
  Require(max_iterations >= 1, "max_iterations must be >= 1");
  Require(huber_m > 0.0, "huber_m must be > 0");
  Require(converged_m > 0.0 && converged_deg > 0.0, "convergence thresholds must be > 0");
  Require(min_matches >= 6, "min_matches must be >= 6");
  Require(max_rms_m > 0.0, "max_rms_m must be > 0");
}

const char* RegistrationStatusName(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::kConverged: return "converged";
    case RegistrationStatus::kTooFewPoints: return "too_few_points";
    case RegistrationStatus::kNotConverged: return "not_converged";
    case RegistrationStatus::kDegenerate: return "degenerate";
    case RegistrationStatus::kNoClaw: return "no_claw";
  }
  return "unknown";
}

ClawRegistration::ClawRegistration(const ClawRegistrationConfig& config) : config_(config) {
  config_.Validate();
}

void ClawRegistration::SetClaw(const TriangleMesh& claw_G) {
  model_points_G_.clear();
  model_normals_G_.clear();
  model_box_G_.setEmpty();
  const double per_m2 = 1.0 / (config_.model_spacing_m * config_.model_spacing_m);
  double carry = 0.0;  // fractional samples carried between triangles
  for (const Eigen::Vector3i& t : claw_G.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || static_cast<size_t>(t[k]) >= claw_G.vertices.size()) {
        throw std::invalid_argument("ClawRegistration::SetClaw: triangle index out of range");
      }
    }
    const Eigen::Vector3d a = claw_G.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = claw_G.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = claw_G.vertices[t[2]].cast<double>();
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area = 0.5 * cross.norm();
    if (!(area > 0.0)) continue;
    const Eigen::Vector3f normal = (cross / (2.0 * area)).cast<float>();
    carry += area * per_m2;
    const int count = static_cast<int>(carry);
    carry -= count;
    for (int s = 0; s < count; ++s) {
      const double r1 = std::fmod(0.5 + kR2a * (s + 1), 1.0);
      const double r2 = std::fmod(0.5 + kR2b * (s + 1), 1.0);
      const double sq = std::sqrt(r1);
      const Eigen::Vector3d p = (1.0 - sq) * a + sq * (1.0 - r2) * b + sq * r2 * c;
      model_points_G_.push_back(p.cast<float>());
      model_normals_G_.push_back(normal);
      model_box_G_.extend(p.cast<float>());
    }
  }
  if (model_points_G_.empty()) return;
  fine_.Build(model_points_G_, 1, config_.fine_cell_m, config_.fine_band_m);
  // The coarse table needs no finer samples than its cells.
  const int coarse_stride = std::max(
      1, static_cast<int>(std::pow(config_.coarse_cell_m / config_.model_spacing_m, 2.0) / 2.0));
  coarse_.Build(model_points_G_, coarse_stride, config_.coarse_cell_m, config_.coarse_band_m);
  // CollectCandidates visits ~10 x max_points pixels; room for all.
  const size_t reserve = static_cast<size_t>(12 * config_.max_points);
  points_C_.reserve(reserve);
  normals_C_.reserve(reserve);
}

int ClawRegistration::CollectCandidates(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G,
                                        double gate_m) {
  points_C_.clear();
  normals_C_.clear();
  const CameraIntrinsics& K = frame.intrinsics;
  if (K.width <= 0 || K.height <= 0 ||
      frame.depth_m.size() != static_cast<size_t>(K.width) * K.height) {
    return 0;
  }
  Eigen::AlignedBox3f box_G = model_box_G_;
  box_G.min().array() -= static_cast<float>(gate_m);
  box_G.max().array() += static_cast<float>(gate_m);
  double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
  double zmin = umin, zmax = -umin;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d p_C =
        T_C_G * box_G.corner(static_cast<Eigen::AlignedBox3f::CornerType>(k)).cast<double>();
    if (p_C.z() < kMinDepthM) return 0;
    const double u = K.fx * p_C.x() / p_C.z() + K.cx, v = K.fy * p_C.y() / p_C.z() + K.cy;
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
    zmin = std::min(zmin, p_C.z());
    zmax = std::max(zmax, p_C.z());
  }
  const int step = config_.normal_step_px;
  const int u0 = std::max(step, static_cast<int>(std::floor(umin)));
  const int u1 = std::min(K.width - 1 - step, static_cast<int>(std::ceil(umax)));
  const int v0 = std::max(step, static_cast<int>(std::floor(vmin)));
  const int v1 = std::min(K.height - 1 - step, static_cast<int>(std::ceil(vmax)));
  if (u0 > u1 || v0 > v1) return 0;
  // Visit about 10x the points kept: most pixels in the box are the object
  // or the background.
  const double area = static_cast<double>(u1 - u0 + 1) * (v1 - v0 + 1);
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(area / (10.0 * config_.max_points)))));
  const Eigen::Isometry3f T_G_C = T_C_G.inverse().cast<float>();
  const float fx = static_cast<float>(K.fx), fy = static_cast<float>(K.fy);
  const float cx = static_cast<float>(K.cx), cy = static_cast<float>(K.cy);
  const float jump = static_cast<float>(config_.normal_max_jump_m);
  const float* depth = frame.depth_m.data();
  const int W = K.width;
  auto point = [&](int u, int v, float z) {
    return Eigen::Vector3f((u - cx) / fx * z, (v - cy) / fy * z, z);
  };
  const size_t cap = points_C_.capacity();
  for (int v = v0; v <= v1; v += stride) {
    for (int u = u0; u <= u1; u += stride) {
      const float z = depth[v * W + u];
      if (!(z > 0.0f) || z < zmin || z > zmax) continue;
      const Eigen::Vector3f p_C = point(u, v, z);
      if (!box_G.contains(T_G_C * p_C)) continue;
      const float zl = depth[v * W + u - step], zr = depth[v * W + u + step];
      const float zu = depth[(v - step) * W + u], zd = depth[(v + step) * W + u];
      if (!(zl > 0.0f && zr > 0.0f && zu > 0.0f && zd > 0.0f)) continue;
      if (std::abs(zl - z) > jump || std::abs(zr - z) > jump || std::abs(zu - z) > jump ||
          std::abs(zd - z) > jump) {
        continue;
      }
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
  // An even subsample down to max_points.
  const size_t keep = static_cast<size_t>(config_.max_points);
  if (points_C_.size() > keep) {
    const double every = static_cast<double>(points_C_.size()) / keep;
    for (size_t i = 0; i < keep; ++i) {
      const size_t from = static_cast<size_t>(i * every);
      points_C_[i] = points_C_[from];
      normals_C_[i] = normals_C_[from];
    }
    points_C_.resize(keep);
    normals_C_.resize(keep);
  }
  return static_cast<int>(points_C_.size());
}

RegistrationResult ClawRegistration::Register(const DepthFrame& frame,
                                              const Eigen::Isometry3d& T_C_G_initial,
                                              double initial_gate_m) {
  RegistrationResult result;
  result.T_C_G = T_C_G_initial;
  if (!has_claw()) return result;
  double gate = std::min(std::max(initial_gate_m, config_.final_gate_m), config_.coarse_band_m);
  result.candidates = CollectCandidates(frame, T_C_G_initial, gate);
  if (result.candidates < config_.min_matches) {
    result.status = RegistrationStatus::kTooFewPoints;
    return result;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points_C_) centre += p.cast<double>();
  centre /= static_cast<double>(points_C_.size());

  const float cos_min = static_cast<float>(std::cos(config_.max_normal_angle_deg * kDegToRad));
  const double huber = config_.huber_m;
  Eigen::Isometry3d T = T_C_G_initial;
  bool converged = false;
  bool settled = false;  // the last step at the final gate was small
  result.status = RegistrationStatus::kNotConverged;
  for (int it = 0; it < config_.max_iterations; ++it) {
    const bool at_final = gate <= config_.final_gate_m * (1.0 + 1e-9);
    const ClosestPointGrid& grid = gate > config_.fine_band_m ? coarse_ : fine_;
    const Eigen::Isometry3f T_G_C = T.inverse().cast<float>();
    const Eigen::Matrix3f R_C_G = T.linear().cast<float>();
    const Eigen::Vector3f t_C_G = T.translation().cast<float>();
    const float gate2 = static_cast<float>(gate * gate);
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    int matches = 0;
    double sum_r2 = 0.0;
    Eigen::Vector3d sum_p = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < points_C_.size(); ++i) {
      const Eigen::Vector3f p_G = T_G_C * points_C_[i];
      const int idx = grid.Nearest(p_G);
      if (idx < 0) continue;
      const Eigen::Vector3f& q_G = model_points_G_[idx];
      const Eigen::Vector3f& m_G = model_normals_G_[idx];
      const Eigen::Vector3f d = p_G - q_G;
      if (d.squaredNorm() > gate2) continue;
      if ((T_G_C.linear() * normals_C_[i]).dot(m_G) < cos_min) continue;
      const double r = m_G.dot(d);
      const Eigen::Vector3d q_C = (R_C_G * q_G + t_C_G).cast<double>() - centre;
      const Eigen::Vector3d m_C = (R_C_G * m_G).cast<double>();
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = -q_C.cross(m_C) / kLeverM;  // rotation as a length at kLeverM
      J.tail<3>() = -m_C;
      const double w = std::abs(r) <= huber ? 1.0 : huber / std::abs(r);
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * r * J;
      sum_r2 += r * r;
      sum_p += points_C_[i].cast<double>();
      ++matches;
    }
    result.iterations = it + 1;
    result.matches = matches;
    result.rms_m = matches > 0 ? std::sqrt(sum_r2 / matches) : 0.0;
    if (matches > 0) result.centroid_C = sum_p / matches;
    if (matches < config_.min_matches) {
      result.status = RegistrationStatus::kTooFewPoints;
      break;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H, Eigen::EigenvaluesOnly);
    if (!(eig.eigenvalues()(0) > kMinConditioning * eig.eigenvalues()(5))) {
      result.status = RegistrationStatus::kDegenerate;
      break;
    }
    const Eigen::Matrix<double, 6, 1> xi = -H.ldlt().solve(g);
    const Eigen::Vector3d w = xi.head<3>() / kLeverM;
    const Eigen::Vector3d v = xi.tail<3>();
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    const double angle = w.norm();
    if (angle > 0.0) D.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    D.translation() = centre + v - D.linear() * centre;  // about the claw's centre
    T = D * T;
    if (at_final && v.norm() < config_.converged_m && angle < config_.converged_deg * kDegToRad) {
      converged = true;
      break;
    }
    settled = at_final && v.norm() < kSettledFactor * config_.converged_m &&
              angle < kSettledFactor * config_.converged_deg * kDegToRad;
    gate = std::max(config_.final_gate_m, gate * config_.gate_shrink);
  }
  // Correspondences switching back and forth at the gate's edge can leave
  // a limit cycle a few times the threshold: converged too.
  if (converged || (result.status == RegistrationStatus::kNotConverged && settled)) {
    result.status = result.rms_m <= config_.max_rms_m ? RegistrationStatus::kConverged
                                                       : RegistrationStatus::kNotConverged;
  }
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.T_C_G = T;
  result.correction_C = T * T_C_G_initial.inverse();
  return result;
}

}  // namespace graspfill::refine
