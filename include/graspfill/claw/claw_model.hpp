// SPDX-License-Identifier: BSD-3-Clause
// The claw (gripper) as a kinematic tree of rigid links with meshes, posed by
// its opening or its joint values. Built-in procedural claws (three-finger as
// in the paper, two-finger parallel) and claws loaded from a description file
// (JSON: links, meshes, fixed transforms, revolute/prismatic joints) so that a
// real robot's meshes (Robotiq 3-Finger, Franka hand) can be used.
//
// Gripper frame G: origin at the centre of the palm face, +z the approach
// direction (from the palm towards the fingertips and the object).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "graspfill/types.hpp"

namespace graspfill::claw {

/// Dimensions of graspfill's procedural claws. Defaults give a claw sized
/// for the paper's objects (5..10 cm wide).
struct ProceduralClawConfig {
  double palm_radius_m{0.07};        ///< radius of the palm (a thin prism)
  double palm_thickness_m{0.02};     ///< palm spans z in [-thickness, 0]
  double finger_length_m{0.09};      ///< fingers span z in [0, length]
  double finger_width_m{0.022};      ///< tangential width of a finger
  double finger_thickness_m{0.012};  ///< radial thickness of a finger
  double min_opening_m{0.005};       ///< joint limits of the radial fingers
  double max_opening_m{0.08};
};

enum class JointType { kFixed, kRevolute, kPrismatic };

/// A joint placing a link in its parent: T_parent_link =
/// T_parent_joint * motion(axis, value). The value is either
/// `joint_bias + joint_scale * joint_values[joint_index]` (URDF mimic joints
/// follow their master's value that way) or `offset + gain * opening`,
/// clamped to limits.
struct Joint {
  JointType type{JointType::kFixed};
  Eigen::Isometry3d T_parent_joint{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d axis{0, 0, 1};  ///< unit, in the joint frame
  double lower{0.0};
  double upper{0.0};
  double gain{1.0};         ///< d(value)/d(opening)
  double offset{0.0};       ///< value at opening 0
  int joint_index{-1};      ///< index into GripperState::joint_values, or -1
  double joint_scale{1.0};  ///< d(value)/d(joint_values[joint_index])
  double joint_bias{0.0};   ///< value at joint_values[joint_index] = 0
};

/// One rigid link. `parent` indexes an earlier link, -1 for the root (G).
struct Link {
  std::string name;
  int parent{-1};
  Joint joint;
  Eigen::Isometry3d T_link_mesh{Eigen::Isometry3d::Identity()};
  TriangleMesh mesh;  ///< in the mesh frame, meters
  /// Zero-area triangles the loader removed from the mesh file (reported,
  /// not an error: exported meshes often have a few).
  int degenerate_triangles_dropped{0};
};

class ClawModel {
 public:
  /// Three fingers at 120 degrees, radial prismatic joints (opening = radius
  /// of the fingers' inner faces), palm at z <= 0.
  static ClawModel ThreeFinger(const ProceduralClawConfig& config = {});
  /// Two parallel fingers facing each other along G's x axis.
  static ClawModel Parallel(const ProceduralClawConfig& config = {});
  /// Loads a description file (format in config/claws/README.md); mesh paths
  /// are relative to the file unless `mesh_root` is given. A URDF claw (a
  /// `.urdf` file, or a JSON config with a "urdf" key) is read by
  /// LoadUrdfClaw (urdf_claw.hpp). Every mesh is checked (mesh_check.hpp).
  /// Throws std::runtime_error with the offending path/field/link on bad
  /// input.
  static ClawModel Load(const std::string& description_path, const std::string& mesh_root = "");
  /// A description's JSON text from elsewhere (a session description on
  /// the bus or in a log), read from memory: its meshes only under the
  /// local `mesh_root` (mesh_path.hpp: relative, no '..'; none without a
  /// root). `name` when the text has none; `label` prefixes the errors.
  static ClawModel LoadDescriptionText(const std::string& text, const std::string& name,
                                       const std::string& label, const std::string& mesh_root);

  /// The claw's surface in G at this opening (and joint values, if given:
  /// they override the opening for the joints that name an index).
  TriangleMesh Posed(double opening_m, const std::vector<double>& joint_values = {}) const;
  /// Poses of every link in G (same order as links()).
  std::vector<Eigen::Isometry3d> LinkPoses(double opening_m,
                                           const std::vector<double>& joint_values = {}) const;

  const std::string& name() const { return name_; }
  const std::vector<Link>& links() const { return links_; }
  /// What the claw's opening means (units, range), from the description.
  const std::string& opening_doc() const { return opening_doc_; }

  /// Links must list parents before children, and every mesh must pass
  /// MeshDefect (throws std::invalid_argument naming the claw and link
  /// otherwise); movable joint axes are normalized.
  ClawModel(std::string name, std::vector<Link> links, std::string opening_doc = "");

 private:
  std::string name_;
  std::vector<Link> links_;
  std::string opening_doc_;
};

}  // namespace graspfill::claw
