// SPDX-License-Identifier: BSD-3-Clause
#include "synth/paper_protocol.hpp"

#include <cmath>
#include <stdexcept>

#include "graspfill/core/random.hpp"
#include "graspfill/mesh/mesh_geometry.hpp"

namespace graspfill::synth {
namespace {

// A random rotation (uniform quaternion, Shoemake) and a translation within
// 0.5 m: the repair may not rely on the cloud's pose.
Eigen::Isometry3d RandomPose(Rng* rng) {
  const double u1 = rng->Uniform(), u2 = rng->Uniform(), u3 = rng->Uniform();
  const Eigen::Quaterniond q(
      std::sqrt(u1) * std::cos(2 * M_PI * u3), std::sqrt(1 - u1) * std::sin(2 * M_PI * u2),
      std::sqrt(1 - u1) * std::cos(2 * M_PI * u2), std::sqrt(u1) * std::sin(2 * M_PI * u3));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(rng->Uniform() - 0.5, rng->Uniform() - 0.5, rng->Uniform() - 0.5);
  return T;
}

// A claw hole: the surface points within a finger-shaped patch seen along
// the radial direction `dir` (unit, horizontal) at height range [z0, z1],
// tilted by `tilt` about the radial axis. Uses the point's offset in the
// finger's own (tangential, vertical) coordinates.
struct ClawPatch {
  Eigen::Vector2d dir;
  double z_centre, half_width, half_height, tilt;
  bool Contains(const Eigen::Vector3f& p) const {
    const Eigen::Vector2d xy(p.x(), p.y());
    if (xy.dot(dir) <= 0.0) return false;                  // the far side
    const double t = dir.x() * xy.y() - dir.y() * xy.x();  // tangential
    const double z = p.z() - z_centre;
    const double a = std::cos(tilt) * t - std::sin(tilt) * z;
    const double b = std::sin(tilt) * t + std::cos(tilt) * z;
    return std::abs(a) <= half_width && std::abs(b) <= half_height;
  }
};

bool HasFlatTop(Shape shape) { return shape != Shape::kSphere && shape != Shape::kEllipsoid; }

}  // namespace

double TopCutZ(const PaperProtocolConfig& config, double height_m) {
  if (config.top_cut_fraction > 0.0) return height_m * (1.0 - config.top_cut_fraction);
  // 10 um below a flat top: the face's samples go, the walls' stay.
  return HasFlatTop(config.shape) ? height_m - 1e-5 : height_m * (1.0 - config.round_top_cut_fraction);
}

PaperProtocolCloud MakePaperProtocolCloud(const PaperProtocolConfig& config) {
  Eigen::Vector3d size = config.size_m;
  if (size.isZero()) size = DefaultSize(config.shape);
  if (!(size.array() > 0).all() || config.num_points <= 0 || config.num_claw_holes < 0 ||
      !(config.round_top_cut_fraction >= 0.0 && config.round_top_cut_fraction < 1.0) ||
      !(config.top_cut_fraction >= 0.0 && config.top_cut_fraction < 0.5)) {
    throw std::invalid_argument(
        "paper protocol: size and point count must be positive, the cut fraction in [0, 1)");
  }
  const TriangleMesh mesh = MakeShape(config.shape, size);
  const mesh::SurfaceSamples sample =
      mesh::SampleSurface(mesh, config.num_points, DeriveSeed(config.seed, 1));
  const mesh::SurfaceSamples truth = mesh::SampleSurface(mesh, config.num_points, DeriveSeed(config.seed, 2));
  const double height = size.z();
  const double top_z = TopCutZ(config, height);

  // Fingers come down from the top (top grasps: the holes reach the cut)
  // or hold the middle; evenly spread around the axis, the first on +x.
  std::vector<ClawPatch> patches;
  const bool top = config.grasp != GraspWay::kMiddleStraight;
  const double z_centre = top ? top_z - 0.5 * config.claw_hole_height_m + 0.004 : 0.5 * height;
  const double tilt = config.grasp == GraspWay::kTopOblique ? config.oblique_tilt_rad : 0.0;
  for (int i = 0; i < config.num_claw_holes; ++i) {
    const double angle = 2.0 * M_PI * i / config.num_claw_holes;
    patches.push_back({Eigen::Vector2d(std::cos(angle), std::sin(angle)), z_centre,
                       0.5 * config.claw_hole_width_m, 0.5 * config.claw_hole_height_m, tilt});
  }

  PaperProtocolCloud out;
  out.size_m = size;
  Rng rng(DeriveSeed(config.seed, 3));
  if (config.random_pose) out.T_cloud_object = RandomPose(&rng);
  const Eigen::Isometry3f T = out.T_cloud_object.cast<float>();
  for (const Eigen::Vector3f& p : sample.points) {
    if (p.z() > top_z) continue;
    bool in_hole = false;
    for (const ClawPatch& patch : patches) in_hole = in_hole || patch.Contains(p);
    if (!in_hole) out.holey.push_back(T * p);
  }
  for (const Eigen::Vector3f& p : truth.points) out.ground_truth.push_back(T * p);
  for (const ClawPatch& patch : patches) {
    // The hole's centre on the bounding box side, a close enough marker.
    const Eigen::Vector3d c(patch.dir.x() * 0.5 * size.x(), patch.dir.y() * 0.5 * size.y(), z_centre);
    out.claw_hole_centres.push_back(out.T_cloud_object * c);
  }
  return out;
}

}  // namespace graspfill::synth
