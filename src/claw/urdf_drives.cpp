// SPDX-License-Identifier: BSD-3-Clause
// A URDF claw's opening drives: each actuated joint's open and closed ends
// (the config's, else its limits in the order that closes the fingers on
// G's z axis), mimic joints through their masters.
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>

#include "urdf_claw_parts.hpp"

namespace graspfill::claw::urdf_parts {
namespace {

// Mean distance from G's z axis of the given links' vertices.
double MeanRadius(const ClawModel& model, const std::vector<int>& links,
                  const std::vector<double>& joint_values) {
  const std::vector<Eigen::Isometry3d> poses = model.LinkPoses(0.0, joint_values);
  double sum = 0.0;
  size_t n = 0;
  for (const int i : links) {
    const Link& link = model.links()[i];
    const Eigen::Isometry3d T = poses[i] * link.T_link_mesh;
    for (const Eigen::Vector3f& v : link.mesh.vertices) {
      sum += (T * v.cast<double>()).head<2>().norm();
      ++n;
    }
  }
  return n == 0 ? 0.0 : sum / static_cast<double>(n);
}

// Opening drive of an actuated joint: q = open + (closed - open) * opening.
struct Drive {
  double open{0.0};
  double closed{0.0};
  int index{0};
  bool explicit_mapping{false};
};

// Each actuated joint's drive: the config's mapping (checked against the
// joint's limits), else provisionally lower -> upper (OrientDrives decides).
std::map<std::string, Drive> InitialDrives(const std::string& label, const UrdfClawConfig& c,
                                           const std::vector<std::string>& actuated,
                                           const std::vector<Link>& links,
                                           const std::map<std::string, int>& link_of_joint) {
  std::map<std::string, Drive> drives;
  for (size_t k = 0; k < actuated.size(); ++k) {
    const std::string& name = actuated[k];
    const Joint& joint = links[link_of_joint.at(name)].joint;
    Drive d;
    d.index = static_cast<int>(k);
    const auto m = c.joints.find(name);
    if (m != c.joints.end()) {
      if (m->second.joint_index >= 0) d.index = m->second.joint_index;
      if (m->second.has_open_closed) {
        d.explicit_mapping = true;
        d.open = m->second.open;
        d.closed = m->second.closed;
        for (const double q : {d.open, d.closed}) {
          if (q < joint.lower || q > joint.upper) {
            std::ostringstream msg;
            msg << "joints." << name << ": " << q << " outside the joint's limits [" << joint.lower << ", "
                << joint.upper << "] (give limits to override the URDF's)";
            Fail(label, msg.str());
          }
        }
      }
    }
    if (!d.explicit_mapping && std::isfinite(joint.lower)) {
      d.open = joint.lower;  // provisional: sorted out below
      d.closed = joint.upper;
    }
    drives[name] = d;
  }
  std::map<int, std::string> joint_at_index;
  for (const auto& [name, d] : drives) {
    const auto [it, added] = joint_at_index.emplace(d.index, name);
    if (!added) {
      Fail(label, "joints: joint_index " + std::to_string(d.index) + " is both '" + it->second + "' and '" +
                      name + "' (give every actuated joint its own)");
    }
  }
  return drives;
}

// A joint's actuated master through its mimic chain:
// q_joint = scale * q_master + bias.
struct MimicChain {
  std::string master;
  double scale{1.0};
  double bias{0.0};
};

MimicChain MasterOf(const std::string& label, const urdf::ModelInterface& model, const std::string& name) {
  std::string current = name;
  std::set<std::string> seen;
  double scale = 1.0;
  double bias = 0.0;
  while (true) {
    const urdf::JointConstSharedPtr j = model.getJoint(current);
    if (!j->mimic) break;
    if (!seen.insert(current).second) Fail(label, "joint '" + name + "': mimic cycle");
    const urdf::JointConstSharedPtr m = model.getJoint(j->mimic->joint_name);
    if (!m) {
      Fail(label, "joint '" + current + "': mimics unknown joint '" + j->mimic->joint_name + "'");
    }
    // q_current = multiplier * q_next + offset
    bias = scale * j->mimic->offset + bias;
    scale *= j->mimic->multiplier;
    current = m->name;
  }
  return {current, scale, bias};
}

std::vector<std::vector<int>> ChildrenOf(const std::vector<Link>& links) {
  std::vector<std::vector<int>> children(links.size());
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].parent >= 0) children[links[i].parent].push_back(static_cast<int>(i));
  }
  return children;
}

// The links each actuated joint moves (its own subtree and every mimic's).
std::map<std::string, std::vector<int>> MovedLinks(const std::string& label,
                                                   const urdf::ModelInterface& model,
                                                   const std::vector<Link>& links,
                                                   const std::vector<std::vector<int>>& children,
                                                   const std::map<std::string, int>& link_of_joint,
                                                   const std::map<std::string, Drive>& drives) {
  std::map<std::string, std::vector<int>> moved;
  for (const auto& [name, link_index] : link_of_joint) {
    if (links[link_index].joint.type == JointType::kFixed) continue;
    const std::string master = MasterOf(label, model, name).master;
    if (drives.count(master) == 0) {
      Fail(label, "joint '" + name + "': mimics '" + master + "', which does not move");
    }
    std::vector<int> todo = {link_index};
    while (!todo.empty()) {
      const int i = todo.back();
      todo.pop_back();
      moved[master].push_back(i);
      for (const int ch : children[i]) todo.push_back(ch);
    }
  }
  return moved;
}

// Writes the drives into the movable joints (mimics through their chain).
void ApplyDrives(const std::string& label, const urdf::ModelInterface& model,
                 const std::map<std::string, int>& link_of_joint, const std::map<std::string, Drive>& drives,
                 std::vector<Link>* links) {
  for (const auto& [name, link_index] : link_of_joint) {
    Joint& joint = (*links)[link_index].joint;
    if (joint.type == JointType::kFixed) continue;
    const MimicChain chain = MasterOf(label, model, name);
    const Drive& d = drives.at(chain.master);
    joint.joint_index = d.index;
    joint.joint_scale = chain.scale;
    joint.joint_bias = chain.bias;
    joint.offset = chain.bias + chain.scale * d.open;
    joint.gain = chain.scale * (d.closed - d.open);
  }
}

// Default rule: "closed" is the limit that brings the joint's fingertips
// nearer G's z axis. Joints are decided from the palm outwards, each with
// the joints before it half-closed (a grasping posture; with them open, an
// under-actuated hand's distal joint, which counter-rotates as the finger
// curls, would be judged backwards) and those after at their lower limits.
// `links` carry the provisional drives.
void OrientDrives(const std::string& label, const urdf::ModelInterface& model, const std::vector<Link>& links,
                  const std::vector<std::vector<int>>& children,
                  const std::map<std::string, std::vector<int>>& moved, int max_index,
                  std::map<std::string, Drive>* drives) {
  std::vector<double> at_open(max_index + 1, 0.0);  // the posture judged in
  for (const auto& [name, d] : *drives) at_open[d.index] = d.open;
  const ClawModel probe(label, links);
  for (const Link& link : links) {
    if (link.parent < 0 || link.joint.type == JointType::kFixed) continue;
    const urdf::JointConstSharedPtr joint = model.getLink(link.name)->parent_joint;
    const auto it = drives->find(joint->name);
    if (it == drives->end()) continue;  // a mimic
    Drive& d = it->second;
    if (d.explicit_mapping || d.open == d.closed) continue;
    const std::vector<int>& all = moved.at(joint->name);
    std::vector<int> tips;
    for (const int i : all) {
      if (children[i].empty() && !links[i].mesh.empty()) tips.push_back(i);
    }
    if (tips.empty()) tips = all;
    std::vector<double> at_upper = at_open;
    at_upper[d.index] = d.closed;
    if (MeanRadius(probe, tips, at_open) < MeanRadius(probe, tips, at_upper) - 1e-9) {
      std::swap(d.open, d.closed);
    }
    at_open[d.index] = 0.5 * (d.open + d.closed);
  }
}

// What the opening means, when the config does not say: the rule and the
// joint_values order.
std::string DefaultOpeningDoc(const std::map<std::string, Drive>& drives, int max_index) {
  std::vector<std::string> by_index(max_index + 1);
  for (const auto& [joint, d] : drives) by_index[d.index] += (by_index[d.index].empty() ? "" : "/") + joint;
  std::string order_text;
  for (const std::string& s : by_index) order_text += (order_text.empty() ? "" : ", ") + s;
  return "Normalized closure in [0, 1]: 0 = every actuated joint at its open limit, 1 = at its "
         "closed one (the limit that moves the fingertips towards the gripper axis), linear in "
         "between; mimic joints follow. joint_values order: [" +
         order_text + "]";
}

}  // namespace

std::string DriveJoints(const std::string& label, const UrdfClawConfig& c, const urdf::ModelInterface& model,
                        const std::vector<std::string>& actuated,
                        const std::map<std::string, int>& link_of_joint, std::vector<Link>* links) {
  std::map<std::string, Drive> drives = InitialDrives(label, c, actuated, *links, link_of_joint);
  const std::vector<std::vector<int>> children = ChildrenOf(*links);
  const std::map<std::string, std::vector<int>> moved =
      MovedLinks(label, model, *links, children, link_of_joint, drives);
  ApplyDrives(label, model, link_of_joint, drives, links);
  int max_index = 0;
  for (const auto& [name, d] : drives) max_index = std::max(max_index, d.index);
  OrientDrives(label, model, *links, children, moved, max_index, &drives);
  ApplyDrives(label, model, link_of_joint, drives, links);
  return DefaultOpeningDoc(drives, max_index);
}

}  // namespace graspfill::claw::urdf_parts
