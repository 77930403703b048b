// SPDX-License-Identifier: BSD-3-Clause
// ClawModel::Load: claw description files (format in config/claws/README.md).
// Every error names the file and the JSON field it comes from, since these
// files are written by hand for each robot.
#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/claw/claw_model.hpp"
#include "graspfill/claw/mesh_check.hpp"
#include "graspfill/claw/mesh_file.hpp"
#include "graspfill/claw/mesh_path.hpp"
#include "graspfill/claw/urdf_claw.hpp"
#include "graspfill/core/regular_file.hpp"
#include "rpy_rotation.hpp"

namespace graspfill::claw {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Builds "file: field: what" messages, and counts the triangles read.
class Context {
 public:
  /// Every mesh's so far: each file is read against what is left of
  /// kMaxClawTriangles.
  mutable int64_t triangles_read{0};

  explicit Context(std::string file) : file_(std::move(file)) {}
  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw std::runtime_error(file_ + ": " + (field.empty() ? "" : field + ": ") + what);
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// ---- limits (claw_limits.hpp): each check names the field ----

void CheckDescriptionLimit(const Context& ctx, const std::string& field, const std::string& defect) {
  if (!defect.empty()) ctx.Fail(field, defect);
}

void CheckDescriptionEach(const Context& ctx, const Eigen::Vector3d& v, const std::string& field,
                          std::string (*defect)(double)) {
  for (int k = 0; k < 3; ++k) CheckDescriptionLimit(ctx, field + "[" + std::to_string(k) + "]", defect(v[k]));
}

// A movable joint's limits: meters (prismatic) or radians (revolute).
void CheckDescriptionJointLimits(const Context& ctx, const Joint& joint, const std::string& field) {
  const auto defect = joint.type == JointType::kPrismatic ? DistanceDefect : AngleDefect;
  CheckDescriptionLimit(ctx, field + ".lower", defect(joint.lower));
  CheckDescriptionLimit(ctx, field + ".upper", defect(joint.upper));
}

// Before any mesh is read.
void CheckLinkCount(const Context& ctx, size_t count) {
  CheckDescriptionLimit(ctx, "links", LinkCountDefect(static_cast<int64_t>(count)));
}

// A claw of frames only would hide nothing from the camera.
void CheckHasGeometry(const Context& ctx, const std::vector<Link>& links) {
  for (const Link& link : links) {
    if (!link.mesh.empty()) return;
  }
  ctx.Fail("links", "no link has a mesh (a claw of frames only would hide nothing from the camera)");
}

// The whole claw, once built: no point beyond kMaxClawReachM in any pose.
ClawModel WithinReach(const Context& ctx, ClawModel model) {
  if (const std::string defect = ClawReachDefect(model); !defect.empty()) ctx.Fail("", defect);
  return model;
}

// ---- fields ----

double ReadNumber(const Context& ctx, const json& j, const std::string& field) {
  if (!j.is_number()) ctx.Fail(field, "expected a number");
  return j.get<double>();
}

Eigen::Vector3d ReadVector3(const Context& ctx, const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 3) {
    ctx.Fail(field, "expected an array of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    v[k] = ReadNumber(ctx, j[k], field + "[" + std::to_string(k) + "]");
  }
  return v;
}

// {"xyz": [..], "rpy": [..]}, both optional (zero), like a URDF <origin>.
Eigen::Isometry3d ReadPose(const Context& ctx, const json& j, const std::string& field) {
  if (!j.is_object()) ctx.Fail(field, "expected an object {xyz, rpy}");
  for (const auto& [key, value] : j.items()) {
    if (key != "xyz" && key != "rpy") {
      ctx.Fail(field, "unknown key '" + key + "' (expected xyz, rpy)");
    }
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (j.contains("xyz")) {
    T.translation() = ReadVector3(ctx, j["xyz"], field + ".xyz");
    CheckDescriptionEach(ctx, T.translation(), field + ".xyz", DistanceDefect);
  }
  if (j.contains("rpy")) {
    const Eigen::Vector3d rpy = ReadVector3(ctx, j["rpy"], field + ".rpy");
    CheckDescriptionEach(ctx, rpy, field + ".rpy", AngleDefect);
    T.linear() = RotationFromRpy(rpy);
  }
  return T;
}

// Link, joint and drive objects are checked for unknown keys: a misspelt
// optional key ("mesh_orgin") would otherwise be silently ignored.
void CheckKeys(const Context& ctx, const json& j, const std::string& field,
               std::initializer_list<const char*> allowed) {
  for (const auto& item : j.items()) {
    // Not a structured binding: clang (the fuzz build) cannot capture one.
    const std::string key = item.key();
    if (key == "doc") continue;  // free text anywhere
    if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }) ==
        allowed.end()) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      ctx.Fail(field, "unknown key '" + key + "' (expected " + list + ")");
    }
  }
}

const json* Find(const json& j, const char* key) {
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

std::string ReadString(const Context& ctx, const json& j, const std::string& field) {
  if (!j.is_string()) ctx.Fail(field, "expected a string");
  return j.get<std::string>();
}

Joint ReadJoint(const Context& ctx, const json& j, const std::string& field) {
  if (!j.is_object()) ctx.Fail(field, "expected an object");
  CheckKeys(ctx, j, field, {"type", "origin", "axis", "limits", "drive"});
  Joint joint;
  const json* type = Find(j, "type");
  if (type == nullptr) ctx.Fail(field + ".type", "missing");
  const std::string type_name = ReadString(ctx, *type, field + ".type");
  if (type_name == "fixed") {
    joint.type = JointType::kFixed;
  } else if (type_name == "revolute") {
    joint.type = JointType::kRevolute;
  } else if (type_name == "prismatic") {
    joint.type = JointType::kPrismatic;
  } else {
    ctx.Fail(field + ".type",
             "unknown joint type '" + type_name + "' (expected fixed, revolute or prismatic)");
  }
  if (const json* origin = Find(j, "origin")) {
    joint.T_parent_joint = ReadPose(ctx, *origin, field + ".origin");
  }
  if (joint.type == JointType::kFixed) return joint;

  const json* axis = Find(j, "axis");
  if (axis == nullptr) ctx.Fail(field + ".axis", "missing (movable joint)");
  joint.axis = ReadVector3(ctx, *axis, field + ".axis");
  if (!(joint.axis.norm() > 1e-9)) ctx.Fail(field + ".axis", "zero vector");
  joint.axis.normalize();

  const json* limits = Find(j, "limits");
  if (limits == nullptr || !limits->is_object()) {
    ctx.Fail(field + ".limits", "missing {lower, upper} (movable joint)");
  }
  const json* lower = Find(*limits, "lower");
  const json* upper = Find(*limits, "upper");
  if (lower == nullptr) ctx.Fail(field + ".limits.lower", "missing");
  if (upper == nullptr) ctx.Fail(field + ".limits.upper", "missing");
  joint.lower = ReadNumber(ctx, *lower, field + ".limits.lower");
  joint.upper = ReadNumber(ctx, *upper, field + ".limits.upper");
  CheckDescriptionJointLimits(ctx, joint, field + ".limits");
  if (joint.lower > joint.upper) {
    ctx.Fail(field + ".limits", "lower > upper");
  }

  const json* drive = Find(j, "drive");
  if (drive == nullptr || !drive->is_object()) {
    ctx.Fail(field + ".drive", "missing {opening_gain, opening_offset} and/or {joint_index}");
  }
  CheckKeys(ctx, *drive, field + ".drive", {"opening_gain", "opening_offset", "joint_index"});
  const json* gain = Find(*drive, "opening_gain");
  const json* offset = Find(*drive, "opening_offset");
  const json* index = Find(*drive, "joint_index");
  if (gain == nullptr && index == nullptr) {
    ctx.Fail(field + ".drive", "needs opening_gain or joint_index");
  }
  // Without an opening drive the joint rests at opening_offset (default 0,
  // clamped to the limits) when no joint values are given.
  joint.gain = gain ? ReadNumber(ctx, *gain, field + ".drive.opening_gain") : 0.0;
  joint.offset = offset ? ReadNumber(ctx, *offset, field + ".drive.opening_offset") : 0.0;
  if (index != nullptr) {
    if (!index->is_number_integer() || index->get<int64_t>() < 0 || index->get<int64_t>() >= kMaxClawLinks) {
      ctx.Fail(field + ".drive.joint_index", "expected an integer 0.." + std::to_string(kMaxClawLinks - 1) +
                                                 " (one per joint; claw_limits.hpp)");
    }
    joint.joint_index = index->get<int>();
  }
  return joint;
}

// Meshes are checked here, where the file and link can still be named.
TriangleMesh ReadMesh(const Context& ctx, const fs::path& path, double scale, const std::string& field,
                      int* degenerate_dropped) {
  TriangleMesh mesh;
  try {
    mesh = ReadMeshFile(path.string(), kMaxClawTriangles - ctx.triangles_read);
  } catch (const std::runtime_error& e) {
    ctx.Fail(field, e.what());
  }
  ctx.triangles_read += static_cast<int64_t>(mesh.triangles.size());
  if (const std::string defect = MeshDefect(mesh); !defect.empty()) {
    ctx.Fail(field, path.string() + ": " + defect);
  }
  for (Eigen::Vector3f& v : mesh.vertices) v *= static_cast<float>(scale);
  if (const std::string defect = MeshExtentDefect(mesh); !defect.empty()) {
    ctx.Fail(field, path.string() + ": " + defect);
  }
  *degenerate_dropped = DropDegenerateTriangles(&mesh);
  if (mesh.empty()) ctx.Fail(field, path.string() + ": every triangle has zero area");
  return mesh;
}

// Where a link's mesh file is: a local file's references are the user's
// own (relative to mesh_dir, or absolute); text from elsewhere is confined
// to the local mesh root.
struct MeshPlace {
  fs::path mesh_dir;
  bool confined{false};
  fs::path Resolve(const Context& ctx, const std::string& field, const std::string& ref) const {
    if (!confined) {
      const fs::path rel = ref;
      return rel.is_absolute() ? rel : mesh_dir / rel;
    }
    try {
      return ConfinedMeshPath(mesh_dir.string(), ref);
    } catch (const std::runtime_error& e) {
      ctx.Fail(field, e.what());
    }
  }
};

// links[i] of a description: its name (unique: index_of), joint, mesh
// origin and mesh; *parent_name: its parent's name ("" for a root).
Link ReadLink(const Context& ctx, const json& j, size_t i, const MeshPlace& meshes,
              std::map<std::string, int>* index_of, std::string* parent_name) {
  std::string field = "links[" + std::to_string(i) + "]";
  if (!j.is_object()) ctx.Fail(field, "expected an object");
  const json* name_json = Find(j, "name");
  if (name_json == nullptr) ctx.Fail(field + ".name", "missing");
  Link link;
  link.name = ReadString(ctx, *name_json, field + ".name");
  field += " (" + link.name + ")";
  CheckKeys(ctx, j, field, {"name", "parent", "joint", "mesh", "mesh_origin", "mesh_scale"});
  if (!index_of->emplace(link.name, static_cast<int>(i)).second) {
    ctx.Fail(field + ".name", "duplicate link name");
  }
  if (const json* p = Find(j, "parent"); p != nullptr && !p->is_null()) {
    *parent_name = ReadString(ctx, *p, field + ".parent");
  }
  if (const json* joint = Find(j, "joint")) {
    link.joint = ReadJoint(ctx, *joint, field + ".joint");
  }
  if (const json* origin = Find(j, "mesh_origin")) {
    link.T_link_mesh = ReadPose(ctx, *origin, field + ".mesh_origin");
  }
  double scale = 1.0;
  if (const json* s = Find(j, "mesh_scale")) {
    scale = ReadNumber(ctx, *s, field + ".mesh_scale");
    if (!(scale > 0.0)) ctx.Fail(field + ".mesh_scale", "must be > 0");
    CheckDescriptionLimit(ctx, field + ".mesh_scale", ScaleDefect(scale));
  }
  if (const json* mesh = Find(j, "mesh")) {
    const std::string ref = ReadString(ctx, *mesh, field + ".mesh");
    link.mesh = ReadMesh(ctx, meshes.Resolve(ctx, field + ".mesh", ref), scale, field + ".mesh",
                         &link.degenerate_triangles_dropped);
  }
  return link;
}

// Each link's parent's position in the file (-1: a root).
std::vector<int> ParentIndices(const Context& ctx, const std::vector<Link>& parsed,
                               const std::vector<std::string>& parent_names,
                               const std::map<std::string, int>& index_of) {
  const int n = static_cast<int>(parsed.size());
  std::vector<int> parent_index(n, -1);
  for (int i = 0; i < n; ++i) {
    if (parent_names[i].empty()) continue;
    const auto it = index_of.find(parent_names[i]);
    if (it == index_of.end()) {
      ctx.Fail("links[" + std::to_string(i) + "] (" + parsed[i].name + ").parent",
               "unknown parent link '" + parent_names[i] + "'");
    }
    parent_index[i] = it->second;
  }
  return parent_index;
}

// The links' file positions parents-first (the file may list them in any
// order); *new_index: each file position's place in that order. A parent
// cycle fails.
std::vector<int> ParentsFirst(const Context& ctx, const std::vector<Link>& parsed,
                              const std::vector<int>& parent_index, std::vector<int>* new_index) {
  const int n = static_cast<int>(parsed.size());
  std::vector<int> order;
  new_index->assign(n, -1);
  std::vector<int> state(n, 0);  // 0 new, 1 on the stack, 2 placed
  for (int start = 0; start < n; ++start) {
    std::vector<int> chain;
    for (int i = start; i >= 0 && state[i] != 2; i = parent_index[i]) {
      if (state[i] == 1) {
        ctx.Fail("links (" + parsed[i].name + ")", "parent cycle");
      }
      state[i] = 1;
      chain.push_back(i);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      state[*it] = 2;
      (*new_index)[*it] = static_cast<int>(order.size());
      order.push_back(*it);
    }
  }
  return order;
}

// The claw of a parsed description; `name` unless it names itself.
ClawModel FromDescription(const Context& ctx, const json& doc, std::string name, const MeshPlace& meshes) {
  if (!doc.is_object()) ctx.Fail("", "bad JSON: top level must be an object");
  if (const json* j = Find(doc, "name")) name = ReadString(ctx, *j, "name");
  std::string opening_doc;
  if (const json* j = Find(doc, "opening_doc")) {
    opening_doc = ReadString(ctx, *j, "opening_doc");
  }
  Eigen::Isometry3d T_G_root = Eigen::Isometry3d::Identity();
  if (const json* j = Find(doc, "T_G_root")) {
    T_G_root = ReadPose(ctx, *j, "T_G_root");
  }
  const json* links_json = Find(doc, "links");
  if (links_json == nullptr || !links_json->is_array() || links_json->empty()) {
    ctx.Fail("links", "missing or empty (expected an array of links)");
  }
  CheckLinkCount(ctx, links_json->size());

  std::vector<Link> parsed;
  std::vector<std::string> parent_names;
  std::map<std::string, int> index_of;
  for (size_t i = 0; i < links_json->size(); ++i) {
    std::string parent;
    parsed.push_back(ReadLink(ctx, (*links_json)[i], i, meshes, &index_of, &parent));
    parent_names.push_back(parent);
  }
  const std::vector<int> parent_index = ParentIndices(ctx, parsed, parent_names, index_of);
  std::vector<int> new_index;
  const std::vector<int> order = ParentsFirst(ctx, parsed, parent_index, &new_index);
  CheckHasGeometry(ctx, parsed);
  std::vector<Link> links;
  links.reserve(parsed.size());
  for (const int i : order) {
    Link link = std::move(parsed[i]);
    link.parent = parent_index[i] < 0 ? -1 : new_index[parent_index[i]];
    // Roots hang from G through the root transform.
    if (link.parent < 0) {
      link.joint.T_parent_joint = T_G_root * link.joint.T_parent_joint;
    }
    links.push_back(std::move(link));
  }
  return WithinReach(ctx, ClawModel(name, std::move(links), opening_doc));
}

}  // namespace

ClawModel ClawModel::Load(const std::string& description_path, const std::string& mesh_root) {
  if (IsUrdfClaw(description_path)) return LoadUrdfClaw(description_path, mesh_root);
  const Context ctx(description_path);
  // "cannot open claw description file 'F': <why>" (a FIFO refused unopened).
  const std::string text =
      ReadRegularFile(description_path, kMaxClawFileBytes, "cannot open claw description file");
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // also a number out of range
    ctx.Fail("", std::string("bad JSON: ") + e.what());
  }
  MeshPlace meshes;
  meshes.mesh_dir = mesh_root.empty() ? fs::path(description_path).parent_path() : fs::path(mesh_root);
  return FromDescription(ctx, doc, fs::path(description_path).stem().string(), meshes);
}

ClawModel ClawModel::LoadDescriptionText(const std::string& text, const std::string& name,
                                         const std::string& label, const std::string& mesh_root) {
  const Context ctx(label);
  if (text.size() > static_cast<size_t>(kMaxClawFileBytes)) {
    ctx.Fail("", std::to_string(text.size()) + " bytes, beyond the " + std::to_string(kMaxClawFileBytes) +
                     "-byte limit of a claw file");
  }
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    ctx.Fail("", std::string("bad JSON: ") + e.what());
  }
  MeshPlace meshes;
  meshes.mesh_dir = mesh_root;
  meshes.confined = true;
  return FromDescription(ctx, doc, name, meshes);
}

}  // namespace graspfill::claw
