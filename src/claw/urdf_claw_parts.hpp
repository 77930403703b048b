// SPDX-License-Identifier: BSD-3-Clause
// The pieces of a URDF claw (urdf_claw.cpp) kept in files of their own:
// the claw config (urdf_claw_config.cpp) and the joints' opening drives
// (urdf_drives.cpp) and the links' geometry (urdf_link_geometry.cpp).
// Private to graspfill_claw.
#pragma once

#include <urdf_model/model.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "graspfill/claw/claw_model.hpp"

namespace graspfill::claw::urdf_parts {

/// Throws std::runtime_error "LABEL: WHAT".
[[noreturn]] void Fail(const std::string& label, const std::string& what);
/// Fails with "FIELD: DEFECT" unless `defect` is empty (claw_limits.hpp).
void CheckLimit(const std::string& label, const std::string& field, const std::string& defect);
/// CheckLimit on each of v's three values, named FIELD[k].
void CheckEach(const std::string& label, const Eigen::Vector3d& v, const std::string& field,
               std::string (*defect)(double));

// One joint's explicit mapping.
struct JointMapping {
  bool has_open_closed{false};
  double open{0.0};
  double closed{0.0};
  bool has_limits{false};
  double lower{0.0};
  double upper{0.0};
  int joint_index{-1};
};

enum class GeometryKind { kCollision, kVisual };

struct UrdfClawConfig {
  std::string name;
  std::string opening_doc;
  Eigen::Isometry3d T_G_root{Eigen::Isometry3d::Identity()};
  GeometryKind geometry{GeometryKind::kCollision};
  std::map<std::string, JointMapping> joints;
  std::map<std::string, Eigen::Isometry3d> mesh_origins;  ///< per link
  std::string urdf_text;
  std::filesystem::path urdf_dir;  ///< relative meshes, when no mesh root
  /// Text from elsewhere (a session description): meshes only under the
  /// local mesh root (mesh_path.hpp), urdf_dir never read.
  bool confined{false};
};

/// The config of a URDF claw (config/claws/README.md), every field checked;
/// urdf_text, urdf_dir and confined are the caller's to fill.
UrdfClawConfig ParseConfig(const std::string& label, const nlohmann::json& doc);

/// Fails unless the origin's position is within the claw's limits; `what`
/// names the element or joint.
void CheckOriginLimits(const std::string& label, const std::string& what, const urdf::Pose& origin);
Eigen::Isometry3d ToIsometry(const urdf::Pose& p);

/// The link's geometry of the config's kind in the link frame, read under
/// `root` (several elements are merged; T_link_mesh is a single element's
/// origin, or the config's mesh_origin).
void ReadLinkGeometry(const std::string& label, const urdf::Link& in, const UrdfClawConfig& c,
                      const std::filesystem::path& root, Link* out);

/// Gives every movable joint of `links` its opening drive (the config's
/// mapping, else the default rule: "closed" moves the fingertips towards
/// G's z axis) and its joint_index, mimics through their masters.
/// `actuated`: the movable joints that are no mimic, by name;
/// `link_of_joint`: each joint's child link. Returns the default opening
/// doc (the rule and the joint_values order).
std::string DriveJoints(const std::string& label, const UrdfClawConfig& c, const urdf::ModelInterface& model,
                        const std::vector<std::string>& actuated,
                        const std::map<std::string, int>& link_of_joint, std::vector<Link>* links);

}  // namespace graspfill::claw::urdf_parts
