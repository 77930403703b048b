// SPDX-License-Identifier: BSD-3-Clause
#include "synth/finger_touch.hpp"

#include <algorithm>
#include <limits>

namespace graspfill::synth {
namespace {

// A half-plane n . p <= offset for the triangle clipper.
struct HalfSpace {
  Eigen::Vector3d n;
  double offset;
};

// Largest value of d . p over the parts of the mesh's triangles inside all
// half-spaces (Sutherland-Hodgman clipping: a linear function over a
// clipped convex polygon peaks at one of its vertices, so this is exact).
// Returns -inf if no triangle reaches into the region.
double MaxSupportInRegion(const TriangleMesh& mesh, const Eigen::Vector3d& d,
                          const std::vector<HalfSpace>& region) {
  double best = -std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> polygon;
  std::vector<Eigen::Vector3d> clipped;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    polygon.clear();
    for (int k = 0; k < 3; ++k) polygon.push_back(mesh.vertices[tri[k]].cast<double>());
    for (const HalfSpace& h : region) {
      clipped.clear();
      for (size_t k = 0; k < polygon.size(); ++k) {
        const Eigen::Vector3d& a = polygon[k];
        const Eigen::Vector3d& b = polygon[(k + 1) % polygon.size()];
        const double fa = h.n.dot(a) - h.offset;
        const double fb = h.n.dot(b) - h.offset;
        if (fa <= 0.0) clipped.push_back(a);
        if ((fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0)) {
          clipped.push_back(a + (fa / (fa - fb)) * (b - a));
        }
      }
      polygon.swap(clipped);
      if (polygon.empty()) break;
    }
    for (const Eigen::Vector3d& p : polygon) best = std::max(best, d.dot(p));
  }
  return best;
}

}  // namespace

std::vector<Eigen::Vector3d> FingerDirections(const claw::ClawModel& model) {
  std::vector<Eigen::Vector3d> dirs;
  for (const claw::Link& link : model.links()) {
    if (link.joint.type != claw::JointType::kPrismatic) continue;
    dirs.push_back((link.joint.T_parent_joint.linear() * link.joint.axis).normalized());
  }
  return dirs;
}

std::vector<double> FingerTouchRadii(const TriangleMesh& object_G, const std::vector<Eigen::Vector3d>& dirs,
                                     double finger_width_m, double finger_length_m) {
  std::vector<double> radii;
  for (const Eigen::Vector3d& d : dirs) {
    const Eigen::Vector3d t = Eigen::Vector3d::UnitZ().cross(d);
    const double half_w = 0.5 * finger_width_m;
    const std::vector<HalfSpace> region = {{t, half_w},
                                           {-t, half_w},
                                           {-Eigen::Vector3d::UnitZ(), 0.0},
                                           {Eigen::Vector3d::UnitZ(), finger_length_m}};
    radii.push_back(MaxSupportInRegion(object_G, d, region));
  }
  return radii;
}

}  // namespace graspfill::synth
