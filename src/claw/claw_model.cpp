// SPDX-License-Identifier: BSD-3-Clause
// ClawModel: forward kinematics of the link tree and the procedural claws.
// Loading description files lives in claw_loader.cpp.
#include "graspfill/claw/claw_model.hpp"

#include "graspfill/claw/mesh_check.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace graspfill::claw {
namespace {

// Sides of the palm polygon: enough to look round in a depth image, few
// enough to keep the BVH tiny.
constexpr int kPalmSides = 24;

// Axis-aligned box [lo, hi] with outward-facing (counter-clockwise seen from
// outside) triangles.
TriangleMesh MakeBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleMesh box;
  // Vertex i has x = hi if bit 0 set, y = hi if bit 1, z = hi if bit 2.
  for (int i = 0; i < 8; ++i) {
    box.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                              (i & 4) ? hi.z() : lo.z());
  }
  // Each face as a quad listed counter-clockwise seen from outside.
  const int quads[6][4] = {
      {0, 4, 6, 2},  // -x
      {1, 3, 7, 5},  // +x
      {0, 1, 5, 4},  // -y
      {2, 6, 7, 3},  // +y
      {0, 2, 3, 1},  // -z
      {4, 5, 7, 6},  // +z
  };
  for (const auto& q : quads) {
    box.triangles.emplace_back(q[0], q[1], q[2]);
    box.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return box;
}

// Regular polygon prism about z: radius `radius_m` (vertex circle), z in
// [z_lo, z_hi], outward-facing triangles.
TriangleMesh MakePrism(double radius_m, double z_lo, double z_hi, int sides) {
  TriangleMesh prism;
  const int n = sides;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    const float x = static_cast<float>(radius_m * std::cos(a));
    const float y = static_cast<float>(radius_m * std::sin(a));
    prism.vertices.emplace_back(x, y, static_cast<float>(z_lo));  // i
    prism.vertices.emplace_back(x, y, static_cast<float>(z_hi));  // n + i
  }
  // Re-order so that bottom ring is [0, n) and top ring is [n, 2n).
  std::vector<Eigen::Vector3f> ordered(2 * n);
  for (int i = 0; i < n; ++i) {
    ordered[i] = prism.vertices[2 * i];
    ordered[n + i] = prism.vertices[2 * i + 1];
  }
  prism.vertices = std::move(ordered);
  const int c_lo = 2 * n;
  const int c_hi = 2 * n + 1;
  prism.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(z_lo));
  prism.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(z_hi));
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    prism.triangles.emplace_back(c_hi, n + i, n + j);  // top, normal +z
    prism.triangles.emplace_back(c_lo, j, i);          // bottom, normal -z
    prism.triangles.emplace_back(i, j, n + j);         // side, outward
    prism.triangles.emplace_back(i, n + j, n + i);
  }
  return prism;
}

// The palm plus radial fingers at the given angles about z (radians).
ClawModel MakeRadialClaw(const std::string& name, const ProceduralClawConfig& config,
                         const std::vector<double>& finger_angles_rad) {
  if (!(config.min_opening_m <= config.max_opening_m)) {
    throw std::invalid_argument("ProceduralClawConfig: min_opening_m > max_opening_m");
  }
  std::vector<Link> links;
  Link palm;
  palm.name = "palm";
  palm.mesh = MakePrism(config.palm_radius_m, -config.palm_thickness_m, 0.0, kPalmSides);
  links.push_back(std::move(palm));

  // Finger link frame: x radial (outwards), z along the approach. The inner
  // face lies at x = 0 of the link, so the joint value is its radius.
  const TriangleMesh finger_mesh =
      MakeBox(Eigen::Vector3f(0.0f, static_cast<float>(-0.5 * config.finger_width_m), 0.0f),
              Eigen::Vector3f(static_cast<float>(config.finger_thickness_m),
                              static_cast<float>(0.5 * config.finger_width_m),
                              static_cast<float>(config.finger_length_m)));
  for (size_t i = 0; i < finger_angles_rad.size(); ++i) {
    Link finger;
    finger.name = "finger_" + std::to_string(i);
    finger.parent = 0;
    finger.joint.type = JointType::kPrismatic;
    finger.joint.T_parent_joint.linear() =
        Eigen::AngleAxisd(finger_angles_rad[i], Eigen::Vector3d::UnitZ()).toRotationMatrix();
    finger.joint.axis = Eigen::Vector3d::UnitX();
    finger.joint.lower = config.min_opening_m;
    finger.joint.upper = config.max_opening_m;
    finger.joint.gain = 1.0;
    finger.joint.offset = 0.0;
    finger.mesh = finger_mesh;
    links.push_back(std::move(finger));
  }
  return ClawModel(name, std::move(links),
                   "radius of each finger's inner face from G's z axis [m], " +
                       std::to_string(config.min_opening_m) + " .. " + std::to_string(config.max_opening_m));
}

}  // namespace

ClawModel::ClawModel(std::string name, std::vector<Link> links, std::string opening_doc)
    : name_(std::move(name)), links_(std::move(links)), opening_doc_(std::move(opening_doc)) {
  for (size_t i = 0; i < links_.size(); ++i) {
    const Link& link = links_[i];
    // Parents before children keeps forward kinematics a single pass.
    if (link.parent < -1 || link.parent >= static_cast<int>(i)) {
      throw std::invalid_argument("ClawModel '" + name_ + "': link '" + link.name +
                                  "' must have a parent listed before it");
    }
    // A bad index would only fail in the ray caster, at the first gripper
    // state and far from the file it came from.
    if (const std::string defect = MeshDefect(link.mesh); !defect.empty()) {
      throw std::invalid_argument("ClawModel '" + name_ + "': link '" + link.name + "': mesh: " + defect);
    }
    if (link.joint.type != JointType::kFixed) {
      const double n = link.joint.axis.norm();
      if (!(n > 1e-9)) {
        throw std::invalid_argument("ClawModel '" + name_ + "': link '" + link.name +
                                    "' has a zero joint axis");
      }
      links_[i].joint.axis /= n;
    }
  }
}

ClawModel ClawModel::ThreeFinger(const ProceduralClawConfig& config) {
  return MakeRadialClaw("three_finger", config, {0.0, 2.0 * M_PI / 3.0, 4.0 * M_PI / 3.0});
}

ClawModel ClawModel::Parallel(const ProceduralClawConfig& config) {
  return MakeRadialClaw("parallel", config, {0.0, M_PI});
}

std::vector<Eigen::Isometry3d> ClawModel::LinkPoses(double opening_m,
                                                    const std::vector<double>& joint_values) const {
  std::vector<Eigen::Isometry3d> T_G_link(links_.size(), Eigen::Isometry3d::Identity());
  for (size_t i = 0; i < links_.size(); ++i) {
    const Link& link = links_[i];
    const Joint& joint = link.joint;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (joint.type != JointType::kFixed) {
      const bool from_index =
          joint.joint_index >= 0 && joint.joint_index < static_cast<int>(joint_values.size());
      double value = from_index ? joint.joint_bias + joint.joint_scale * joint_values[joint.joint_index]
                                : joint.offset + joint.gain * opening_m;
      value = std::clamp(value, std::min(joint.lower, joint.upper), std::max(joint.lower, joint.upper));
      if (joint.type == JointType::kPrismatic) {
        motion.translation() = value * joint.axis;
      } else {
        motion.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
      }
    }
    const Eigen::Isometry3d T_parent_link = joint.T_parent_joint * motion;
    T_G_link[i] = link.parent < 0 ? T_parent_link : T_G_link[link.parent] * T_parent_link;
  }
  return T_G_link;
}

TriangleMesh ClawModel::Posed(double opening_m, const std::vector<double>& joint_values) const {
  const std::vector<Eigen::Isometry3d> T_G_link = LinkPoses(opening_m, joint_values);
  TriangleMesh claw_G;
  size_t num_vertices = 0;
  size_t num_triangles = 0;
  for (const Link& link : links_) {
    num_vertices += link.mesh.vertices.size();
    num_triangles += link.mesh.triangles.size();
  }
  claw_G.vertices.reserve(num_vertices);
  claw_G.triangles.reserve(num_triangles);
  for (size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].mesh.empty()) continue;
    claw_G.Append(links_[i].mesh.Transformed(T_G_link[i] * links_[i].T_link_mesh));
  }
  return claw_G;
}

}  // namespace graspfill::claw
