// SPDX-License-Identifier: BSD-3-Clause
// The gated point-to-plane ICP loop shared by the claw registration and the
// object tracker (private to src/refine).
//
// Each iteration matches every observed point to its nearest model point,
// keeps the match when it lies within the iteration's gate and the two
// normals agree, weights its residual (Huber) and sums the normal equations
// of a small rigid motion about `centre`, rotations measured as the motion
// they give at kIcpLeverM (so that the six unknowns share a unit). The
// problem solves them (its own way: a check of the conditioning, damping, a
// shift only) and the pose takes the step on the left. The gate shrinks by
// a factor per iteration down to the final gate; a step at the final gate
// below the thresholds converges.
//
// What differs between the two lives in the Problem, a class with:
//   void SetPose(const Eigen::Isometry3d& pose, double gate_m);  // per iteration
//   size_t size() const;                                        // observed points
//   // Point i and its nearest model point and normal, all in the frame the
//   // residuals are measured in; false: no model point near it.
//   bool Nearest(size_t i, Eigen::Vector3f* p, Eigen::Vector3f* q, Eigen::Vector3f* m) const;
//   Eigen::Vector3f Normal(size_t i) const;  // point i's normal, in that frame
//   // A model point and normal in the frame the pose's step is taken in.
//   void InStepFrame(const Eigen::Vector3f& q, const Eigen::Vector3f& m,
//                    Eigen::Vector3d* q_step, Eigen::Vector3d* m_step) const;
//   void Matched(size_t i);  // point i was kept
//   // The step (rotation vector [rad], translation [m]) from the normal
//   // equations H x = -g; false: none can be taken (the loop ends).
//   bool Step(Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& g,
//             Eigen::Vector3d* w, Eigen::Vector3d* v);
// A template, so that the per-point calls inline in the frame path.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>

namespace graspfill::refine {

constexpr double kIcpDegToRad = 3.14159265358979323846 / 180.0;
// Rotations are measured as the motion they give at this lever arm [m].
constexpr double kIcpLeverM = 0.05;
// A last step within this many convergence thresholds ends the iterations
// as converged (matches switching at the gate's edge: a limit cycle).
constexpr double kIcpSettledFactor = 4.0;

struct GatedIcpSchedule {
  double initial_gate_m{0.0};
  double final_gate_m{0.0};
  double gate_shrink{1.0};
  int max_iterations{0};
  double huber_m{0.0};  // Huber threshold of the residuals [m]
  double max_normal_angle_deg{0.0};
  double converged_m{0.0};  // a step at the final gate below these converges
  double converged_deg{0.0};
  int min_matches{0};  // fewer: the loop ends
};

// The schedule of a config that names these fields as GatedIcpSchedule does.
template <class Config>
GatedIcpSchedule GatedIcpScheduleOf(const Config& config, double initial_gate_m) {
  GatedIcpSchedule schedule;
  schedule.initial_gate_m = initial_gate_m;
  schedule.final_gate_m = config.final_gate_m;
  schedule.gate_shrink = config.gate_shrink;
  schedule.max_iterations = config.max_iterations;
  schedule.huber_m = config.huber_m;
  schedule.max_normal_angle_deg = config.max_normal_angle_deg;
  schedule.converged_m = config.converged_m;
  schedule.converged_deg = config.converged_deg;
  schedule.min_matches = config.min_matches;
  return schedule;
}

// The checks, in this order, of the fields a config for the loop and for
// DepthPixelNormals has besides the schedule's: `require(ok, what)` throws
// when !ok.
template <class Config, class Require>
void RequireSampledIcpFields(const Config& c, Require&& require) {
  require(c.max_points >= 10, "max_points must be >= 10");
  require(c.normal_step_px >= 1, "normal_step_px must be >= 1");
  require(c.normal_max_jump_m > 0.0, "normal_max_jump_m must be > 0");
  require(c.max_normal_angle_deg > 0.0 && c.max_normal_angle_deg <= 180.0,
          "max_normal_angle_deg must be in (0, 180]");
  require(c.gate_shrink > 0.0 && c.gate_shrink <= 1.0, "gate_shrink must be in (0, 1]");
}

enum class GatedIcpEnd {
  kIterationsSpent,  // max_iterations without converging
  kConverged,
  kTooFewMatches,
  kNoStep,  // Problem::Step refused
};

struct GatedIcpOutcome {
  GatedIcpEnd end{GatedIcpEnd::kIterationsSpent};
  // The last step was at the final gate within kIcpSettledFactor of the
  // thresholds (meaningful when the iterations were spent).
  bool settled{false};
  int iterations{0};
  int matches{0};     // of the last iteration
  double rms_m{0.0};  // RMS residual of the last iteration's matches
};

// The full six-motion solution of H x = -g.
inline void SolveFullStep(const Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& g,
                          Eigen::Vector3d* w, Eigen::Vector3d* v) {
  const Eigen::Matrix<double, 6, 1> xi = -H.ldlt().solve(g);
  *w = xi.head<3>() / kIcpLeverM;
  *v = xi.tail<3>();
}

// Point i's match when the problem has one within the gate (squared,
// gate2) whose normal agrees with the point's (cos_min): the residual's
// vector d = p - q, the model point q and its normal m.
template <class Problem>
bool GatedMatch(const Problem& problem, size_t i, float gate2, float cos_min, Eigen::Vector3f* d,
                Eigen::Vector3f* q, Eigen::Vector3f* m) {
  Eigen::Vector3f p;
  if (!problem.Nearest(i, &p, q, m)) return false;
  *d = p - *q;
  return d->squaredNorm() <= gate2 && problem.Normal(i).dot(*m) >= cos_min;
}

// The motion turning by the rotation vector w [rad] about `centre` and
// moving it by v [m].
inline Eigen::Isometry3d MotionAbout(const Eigen::Vector3d& w, const Eigen::Vector3d& v,
                                     const Eigen::Vector3d& centre) {
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  const double angle = w.norm();
  if (angle > 0.0) D.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  D.translation() = centre + v - D.linear() * centre;
  return D;
}

// Runs the loop from *pose (updated in place), stepping about `centre` (in
// the step frame).
template <class Problem>
GatedIcpOutcome RunGatedIcp(const GatedIcpSchedule& schedule, const Eigen::Vector3d& centre, Problem& problem,
                            Eigen::Isometry3d* pose) {
  const float cos_min = static_cast<float>(std::cos(schedule.max_normal_angle_deg * kIcpDegToRad));
  const double huber = schedule.huber_m;
  Eigen::Isometry3d& T = *pose;
  double gate = schedule.initial_gate_m;
  GatedIcpOutcome out;
  for (int it = 0; it < schedule.max_iterations; ++it) {
    const bool at_final = gate <= schedule.final_gate_m * (1.0 + 1e-9);
    problem.SetPose(T, gate);
    const float gate2 = static_cast<float>(gate * gate);
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    int matches = 0;
    double sum_r2 = 0.0;
    for (size_t i = 0; i < problem.size(); ++i) {
      Eigen::Vector3f d, q, m;
      if (!GatedMatch(problem, i, gate2, cos_min, &d, &q, &m)) continue;
      const double r = m.dot(d);
      Eigen::Vector3d q_step, m_step;
      problem.InStepFrame(q, m, &q_step, &m_step);
      q_step -= centre;
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = -q_step.cross(m_step) / kIcpLeverM;  // rotation as a length
      J.tail<3>() = -m_step;
      const double w = std::abs(r) <= huber ? 1.0 : huber / std::abs(r);
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * r * J;
      sum_r2 += r * r;
      problem.Matched(i);
      ++matches;
    }
    out.iterations = it + 1;
    out.matches = matches;
    out.rms_m = matches > 0 ? std::sqrt(sum_r2 / matches) : 0.0;
    if (matches < schedule.min_matches) {
      out.end = GatedIcpEnd::kTooFewMatches;
      return out;
    }
    Eigen::Vector3d w, v;
    if (!problem.Step(H, g, &w, &v)) {
      out.end = GatedIcpEnd::kNoStep;
      return out;
    }
    const double angle = w.norm();
    T = MotionAbout(w, v, centre) * T;
    if (at_final && v.norm() < schedule.converged_m && angle < schedule.converged_deg * kIcpDegToRad) {
      out.end = GatedIcpEnd::kConverged;
      return out;
    }
    out.settled = at_final && v.norm() < kIcpSettledFactor * schedule.converged_m &&
                  angle < kIcpSettledFactor * schedule.converged_deg * kIcpDegToRad;
    gate = std::max(schedule.final_gate_m, gate * schedule.gate_shrink);
  }
  out.end = GatedIcpEnd::kIterationsSpent;
  return out;
}

}  // namespace graspfill::refine
