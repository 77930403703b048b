// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/refine/claw_registration.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "depth_pixel_normals.hpp"
#include "gated_icp.hpp"
#include "graspfill/core/require.hpp"

namespace graspfill::refine {
namespace {

// Box corners nearer than this to the camera plane: no projection.
constexpr double kMinDepthM = 0.05;
// Smallest / largest eigenvalue of the normal equations (rotations about
// the centroid scaled by kIcpLeverM) below this: the matches leave a motion
// unconstrained.
constexpr double kMinConditioning = 1e-5;

// R2 low-discrepancy sequence (Roberts 2018): even, deterministic samples.
constexpr double kR2a = 0.7548776662466927;
constexpr double kR2b = 0.5698402909980532;

// The claw's ICP problem (gated_icp.hpp): depth points in C matched to
// the model in G, residuals measured in G, the step a motion of C about the
// depth points' centre. Also the centroid of the matched points.
class ClawProblem {
 public:
  ClawProblem(const ClosestPointGrid& fine, const ClosestPointGrid& coarse, double fine_band_m,
              const std::vector<Eigen::Vector3f>& model_points_G,
              const std::vector<Eigen::Vector3f>& model_normals_G,
              const std::vector<Eigen::Vector3f>& points_C, const std::vector<Eigen::Vector3f>& normals_C)
      : fine_(fine),
        coarse_(coarse),
        fine_band_m_(fine_band_m),
        model_points_G_(model_points_G),
        model_normals_G_(model_normals_G),
        points_C_(points_C),
        normals_C_(normals_C) {}

  void SetPose(const Eigen::Isometry3d& T_C_G, double gate_m) {
    CloseCentroid();
    grid_ = gate_m > fine_band_m_ ? &coarse_ : &fine_;
    T_G_C_ = T_C_G.inverse().cast<float>();
    R_C_G_ = T_C_G.linear().cast<float>();
    t_C_G_ = T_C_G.translation().cast<float>();
  }
  size_t size() const { return points_C_.size(); }
  bool Nearest(size_t i, Eigen::Vector3f* p_G, Eigen::Vector3f* q_G, Eigen::Vector3f* m_G) const {
    *p_G = T_G_C_ * points_C_[i];
    const int idx = grid_->Nearest(*p_G);
    if (idx < 0) return false;
    *q_G = model_points_G_[idx];
    *m_G = model_normals_G_[idx];
    return true;
  }
  Eigen::Vector3f Normal(size_t i) const { return T_G_C_.linear() * normals_C_[i]; }
  void InStepFrame(const Eigen::Vector3f& q_G, const Eigen::Vector3f& m_G, Eigen::Vector3d* q_C,
                   Eigen::Vector3d* m_C) const {
    *q_C = (R_C_G_ * q_G + t_C_G_).cast<double>();
    *m_C = (R_C_G_ * m_G).cast<double>();
  }
  void Matched(size_t i) {
    sum_p_C_ += points_C_[i].cast<double>();
    ++matched_;
  }
  bool Step(Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& g, Eigen::Vector3d* w,
            Eigen::Vector3d* v) const {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H, Eigen::EigenvaluesOnly);
    if (!(eig.eigenvalues()(0) > kMinConditioning * eig.eigenvalues()(5))) return false;
    SolveFullStep(H, g, w, v);
    return true;
  }

  // The centroid of the last iteration that matched any point.
  bool has_centroid() {
    CloseCentroid();
    return has_centroid_;
  }
  const Eigen::Vector3d& centroid_C() const { return centroid_C_; }

 private:
  void CloseCentroid() {
    if (matched_ > 0) {
      centroid_C_ = sum_p_C_ / matched_;
      has_centroid_ = true;
    }
    sum_p_C_.setZero();
    matched_ = 0;
  }

  const ClosestPointGrid& fine_;
  const ClosestPointGrid& coarse_;
  const double fine_band_m_;
  const std::vector<Eigen::Vector3f>& model_points_G_;
  const std::vector<Eigen::Vector3f>& model_normals_G_;
  const std::vector<Eigen::Vector3f>& points_C_;
  const std::vector<Eigen::Vector3f>& normals_C_;
  const ClosestPointGrid* grid_{nullptr};
  Eigen::Isometry3f T_G_C_;
  Eigen::Matrix3f R_C_G_;
  Eigen::Vector3f t_C_G_;
  Eigen::Vector3d sum_p_C_{Eigen::Vector3d::Zero()};
  int matched_{0};
  Eigen::Vector3d centroid_C_{Eigen::Vector3d::Zero()};
  bool has_centroid_{false};
};

// Gauss-Newton steps of the depth-scale estimate, at most (each
// re-matches; with one, a session at 2% found 1.78%, with up to three
// 1.97%).
constexpr int kScaleSteps = 3;
// A step smaller than this ends them: a frame's own noise is ~0.2%, and
// up to eight steps moved eight views' median estimate by 0.002%.
constexpr double kScaleConverged = 0.003;
// Fewer matches than this tell no scale.
constexpr int kMinScaleMatches = 100;

}  // namespace

void ClawRegistrationConfig::Validate() const {
  Require("ClawRegistrationConfig", model_spacing_m > 0.0, "model_spacing_m must be > 0");
  Require("ClawRegistrationConfig", fine_cell_m > 0.0 && coarse_cell_m > 0.0, "grid cells must be > 0");
  Require("ClawRegistrationConfig", fine_band_m > 0.0 && coarse_band_m >= fine_band_m,
          "bands must be > 0 and coarse_band_m >= fine_band_m");
  RequireSampledIcpFields(
      *this, [](bool ok, const std::string& what) { Require("ClawRegistrationConfig", ok, what); });
  Require("ClawRegistrationConfig", final_gate_m > 0.0 && final_gate_m <= fine_band_m,
          "final_gate_m must be in (0, fine_band_m]");
  Require("ClawRegistrationConfig", max_iterations >= 1, "max_iterations must be >= 1");
  Require("ClawRegistrationConfig", huber_m > 0.0, "huber_m must be > 0");
  Require("ClawRegistrationConfig", converged_m > 0.0 && converged_deg > 0.0,
          "convergence thresholds must be > 0");
  Require("ClawRegistrationConfig", min_matches >= 6, "min_matches must be >= 6");
  Require("ClawRegistrationConfig", max_rms_m > 0.0, "max_rms_m must be > 0");
}

const char* RegistrationStatusName(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::kConverged:
      return "converged";
    case RegistrationStatus::kTooFewPoints:
      return "too_few_points";
    case RegistrationStatus::kNotConverged:
      return "not_converged";
    case RegistrationStatus::kDegenerate:
      return "degenerate";
    case RegistrationStatus::kNoClaw:
      return "no_claw";
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
  const int coarse_stride =
      std::max(1, static_cast<int>(std::pow(config_.coarse_cell_m / config_.model_spacing_m, 2.0) / 2.0));
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
  if (!DepthPixelNormals::Fits(frame)) return 0;
  const CameraIntrinsics& K = frame.intrinsics;
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
  const DepthPixelNormals pixels(K, frame.depth_m.data(), step, config_.normal_max_jump_m);
  const float* depth = frame.depth_m.data();
  const int W = K.width;
  const size_t cap = points_C_.capacity();
  for (int v = v0; v <= v1; v += stride) {
    for (int u = u0; u <= u1; u += stride) {
      const float z = depth[v * W + u];
      if (!(z > 0.0f) || z < zmin || z > zmax) continue;
      const Eigen::Vector3f p_C = pixels.Point(u, v, z);
      if (!box_G.contains(T_G_C * p_C)) continue;
      Eigen::Vector3f n;
      if (!pixels.Normal(u, v, z, p_C, &n)) continue;
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

RegistrationResult ClawRegistration::Register(const DepthFrame& frame, const Eigen::Isometry3d& T_C_G_initial,
                                              double initial_gate_m) {
  RegistrationResult result;
  result.T_C_G = T_C_G_initial;
  if (!has_claw()) return result;
  const double gate = std::min(std::max(initial_gate_m, config_.final_gate_m), config_.coarse_band_m);
  result.candidates = CollectCandidates(frame, T_C_G_initial, gate);
  if (result.candidates < config_.min_matches) {
    result.status = RegistrationStatus::kTooFewPoints;
    return result;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points_C_) centre += p.cast<double>();
  centre /= static_cast<double>(points_C_.size());

  ClawProblem problem(fine_, coarse_, config_.fine_band_m, model_points_G_, model_normals_G_, points_C_,
                      normals_C_);
  Eigen::Isometry3d T = T_C_G_initial;
  const GatedIcpOutcome icp = RunGatedIcp(GatedIcpScheduleOf(config_, gate), centre, problem, &T);
  result.iterations = icp.iterations;
  result.matches = icp.matches;
  result.rms_m = icp.rms_m;
  if (problem.has_centroid()) result.centroid_C = problem.centroid_C();
  switch (icp.end) {
    case GatedIcpEnd::kTooFewMatches:
      result.status = RegistrationStatus::kTooFewPoints;
      break;
    case GatedIcpEnd::kNoStep:
      result.status = RegistrationStatus::kDegenerate;
      break;
    // Correspondences switching back and forth at the gate's edge can leave
    // a limit cycle a few times the threshold: converged too.
    case GatedIcpEnd::kConverged:
    case GatedIcpEnd::kIterationsSpent:
      result.status = (icp.end == GatedIcpEnd::kConverged || icp.settled) && result.rms_m <= config_.max_rms_m
                          ? RegistrationStatus::kConverged
                          : RegistrationStatus::kNotConverged;
      break;
  }
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.T_C_G = T;
  result.correction_C = T * T_C_G_initial.inverse();
  return result;
}

// A depth error s = 1 + e scales each point along its ray: the observed
// p_C is s times the true one, and a match's residual r = m . (p - q)
// becomes m . (p / s - q) once corrected. Solved jointly with a small
// motion of the claw, whose translation takes the part along the mean ray
// (that alone a hand-eye error explains as well): what is left is the
// claw's size. The lever is the model point's (q - centre), not the
// observed one's: the depth noise in both the lever and the residual would
// bias e by sigma^2 / lever^2 (+0.3% at 0.6 m). Unweighted, every match
// within the final gate, re-matched after each step with the points and
// the pose moved by it.
bool ClawRegistration::EstimateDepthScale(const RegistrationResult& registered, DepthScaleSample* sample) {
  if (registered.status != RegistrationStatus::kConverged || points_C_.empty()) return false;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points_C_) centre += p.cast<double>();
  centre /= static_cast<double>(points_C_.size());
  ClawProblem problem(fine_, coarse_, config_.fine_band_m, model_points_G_, model_normals_G_, points_C_,
                      normals_C_);
  const float gate2 = static_cast<float>(config_.final_gate_m * config_.final_gate_m);
  const float cos_min = static_cast<float>(std::cos(config_.max_normal_angle_deg * kIcpDegToRad));
  Eigen::Isometry3d T = registered.T_C_G;
  double scale = 1.0;  // the points are divided by it so far
  for (int step = 0; step < kScaleSteps; ++step) {
    problem.SetPose(T, config_.final_gate_m);
    Eigen::Matrix<double, 7, 7> H = Eigen::Matrix<double, 7, 7>::Zero();
    Eigen::Matrix<double, 7, 1> g = Eigen::Matrix<double, 7, 1>::Zero();
    double sum_r2 = 0.0;
    int n = 0;
    for (size_t i = 0; i < problem.size(); ++i) {
      Eigen::Vector3f d, q, m;
      if (!GatedMatch(problem, i, gate2, cos_min, &d, &q, &m)) continue;
      Eigen::Vector3d q_C, m_C;
      problem.InStepFrame(q, m, &q_C, &m_C);
      const double r = m.dot(d);
      Eigen::Matrix<double, 7, 1> J;
      J.head<3>() = -(q_C - centre).cross(m_C) / kIcpLeverM;
      J.segment<3>(3) = -m_C;
      J(6) = -m_C.dot(q_C - centre);
      H.noalias() += J * J.transpose();
      g.noalias() += r * J;
      sum_r2 += r * r;
      ++n;
    }
    if (n < kMinScaleMatches) return false;
    const Eigen::LDLT<Eigen::Matrix<double, 7, 7>> solve(H);
    if (solve.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 7, 1> x = -solve.solve(g);
    const double variance_factor = solve.solve(Eigen::Matrix<double, 7, 1>::Unit(6))(6);
    if (!x.allFinite() || !(variance_factor > 0.0)) return false;
    // The residuals left after the step: their squares sum to r.r + x.g.
    const double left = std::max(0.0, sum_r2 + x.dot(g));
    sample->stderr_ = std::sqrt(left / (n - 7) * variance_factor);
    sample->matches = n;
    // The step: the points scaled by 1 / (1 + e) about their centre (the
    // lever's origin: the rest of a scale about the camera is the
    // translation's), the claw moved.
    const double e = x(6);
    scale *= 1.0 + e;
    const Eigen::Vector3f centre_f = centre.cast<float>();
    for (Eigen::Vector3f& p : points_C_) p = centre_f + (p - centre_f) / static_cast<float>(1.0 + e);
    T = MotionAbout(x.head<3>() / kIcpLeverM, x.segment<3>(3), centre) * T;
    if (std::abs(e) < kScaleConverged) break;
  }
  sample->error = scale - 1.0;
  return true;
}

}  // namespace graspfill::refine
