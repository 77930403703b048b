// SPDX-License-Identifier: BSD-3-Clause
#include "synth/model_claw_placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspfill/claw/opening_range.hpp"
#include "graspfill/core/raycaster.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"

namespace graspfill::synth {
namespace {

constexpr double kSampleAreaM2 = 2e-6;  // one claw surface sample per 2 mm^2
constexpr int kMaxSamplesPerLink = 40000;
constexpr double kGapStepM = 0.002;
constexpr double kMaxGapM = 0.15;
constexpr int kScanSteps = 48;
constexpr int kBisections = 12;

// The claw's surface samples in link frames, posed per opening.
struct ClawSamples {
  std::vector<std::vector<Eigen::Vector3d>> per_link;
};

ClawSamples SampleClaw(const claw::ClawModel& claw) {
  ClawSamples s;
  for (size_t i = 0; i < claw.links().size(); ++i) {
    const claw::Link& link = claw.links()[i];
    std::vector<Eigen::Vector3d> points;
    if (!link.mesh.empty()) {
      const int count =
          std::clamp(static_cast<int>(mesh::SurfaceArea(link.mesh) / kSampleAreaM2), 64, kMaxSamplesPerLink);
      const mesh::SurfaceSamples samples = mesh::SampleSurface(link.mesh, count, 1000 + i);
      for (const Eigen::Vector3f& p : samples.points) points.push_back(link.T_link_mesh * p.cast<double>());
    }
    s.per_link.push_back(std::move(points));
  }
  return s;
}

// Inside a closed mesh: an odd number of crossings along a fixed skew ray.
class Solid {
 public:
  explicit Solid(const TriangleMesh& mesh) : box_(mesh::Bounds(mesh)) {
    raycaster_.AddMesh(mesh);
    raycaster_.Commit();
  }
  bool Contains(const Eigen::Vector3d& p) const {
    if (!box_.contains(p)) return false;
    const Eigen::Vector3f dir = Eigen::Vector3f(0.5773f, 0.5774f, 0.5775f).normalized();
    const Eigen::Vector3f origin = p.cast<float>();
    int crossings = 0;
    float t_near = 0.0f;
    for (int k = 0; k < 256; ++k) {
      const RayHit hit = raycaster_.Cast(origin, dir, t_near);
      if (!hit.hit()) break;
      ++crossings;
      t_near = hit.t + 1e-6f;
    }
    return crossings % 2 == 1;
  }

 private:
  Raycaster raycaster_;
  Eigen::AlignedBox3d box_;
};

bool Penetrates(const claw::ClawModel& claw, const ClawSamples& samples, const Solid& object,
                double opening) {
  const std::vector<Eigen::Isometry3d> poses = claw.LinkPoses(opening);
  for (size_t i = 0; i < poses.size(); ++i) {
    for (const Eigen::Vector3d& p : samples.per_link[i]) {
      if (object.Contains(poses[i] * p)) return true;
    }
  }
  return false;
}

}  // namespace

ModelClawHold HoldInModelClaw(const claw::ClawModel& claw, const TriangleMesh& object_O,
                              const Eigen::Matrix3d& R_G_O, const Eigen::Vector2d& axis_offset_xy,
                              double min_palm_gap_m) {
  const claw::OpeningRange range = claw::FindOpeningRange(claw);
  const ClawSamples samples = SampleClaw(claw);
  double top_rot = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3f& v : object_O.vertices) {
    top_rot = std::min(top_rot, (R_G_O * v.cast<double>()).z());
  }
  ModelClawHold hold;
  hold.T_G_O.linear() = R_G_O;
  const std::string who = "claw '" + claw.name() + "'";
  for (hold.palm_gap_m = min_palm_gap_m;; hold.palm_gap_m += kGapStepM) {
    if (hold.palm_gap_m > kMaxGapM) {
      throw std::invalid_argument(who + ": the object does not fit in the open claw");
    }
    hold.T_G_O.translation() =
        Eigen::Vector3d(axis_offset_xy.x(), axis_offset_xy.y(), hold.palm_gap_m - top_rot);
    const Solid object(object_O.Transformed(hold.T_G_O));
    if (!Penetrates(claw, samples, object, range.open)) break;
  }
  const Solid object(object_O.Transformed(hold.T_G_O));
  // Close in steps until the first contact, then bisect the step.
  double free = range.open;
  double touching = range.open;
  bool touched = false;
  for (int k = 1; k <= kScanSteps && !touched; ++k) {
    const double opening = range.open + (range.closed - range.open) * k / kScanSteps;
    if (Penetrates(claw, samples, object, opening)) {
      touching = opening;
      touched = true;
    } else {
      free = opening;
    }
  }
  if (!touched) {
    throw std::invalid_argument(who + ": the closed claw does not touch the object");
  }
  for (int k = 0; k < kBisections; ++k) {
    const double mid = 0.5 * (free + touching);
    (Penetrates(claw, samples, object, mid) ? touching : free) = mid;
  }
  hold.opening = free;
  return hold;
}

}  // namespace graspfill::synth
