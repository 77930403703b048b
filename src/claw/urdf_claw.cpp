// SPDX-License-Identifier: BSD-3-Clause
// URDF claws: urdfdom parses the XML, this file turns its link tree into a
// ClawModel and maps graspfill's opening onto the joints (rules in
// config/claws/README.md and docs/claws.md, "Claws from URDF").
#include "graspfill/claw/urdf_claw.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/core/regular_file.hpp"
#include "urdf_claw_parts.hpp"

namespace graspfill::claw {
namespace {

using nlohmann::json;
using namespace urdf_parts;  // the config, the drives, Fail (urdf_claw_parts.hpp)
namespace fs = std::filesystem;

// A regular file only (a FIFO would block), of at most kMaxClawFileBytes.
std::string ReadText(const std::string& path) {
  return ReadRegularFile(path, kMaxClawFileBytes, "cannot open file");
}

std::string LowerCase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool IsUrdfFileName(const std::string& path) {
  return LowerCase(fs::path(path).extension().string()) == ".urdf";
}

// urdfdom reports why it rejects a file through console_bridge: keep its
// errors for our message instead of printing them. Loading is setup-time
// work on one thread; the previous handler is restored.
class CapturedUrdfLog : public console_bridge::OutputHandler {
 public:
  CapturedUrdfLog() : previous_(console_bridge::getOutputHandler()) {
    console_bridge::useOutputHandler(this);
  }
  ~CapturedUrdfLog() override { console_bridge::useOutputHandler(previous_); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && errors_.size() < 400) {
      errors_ += (errors_.empty() ? "" : "; ") + text;
    }
  }
  const std::string& errors() const { return errors_; }

 private:
  console_bridge::OutputHandler* previous_;
  std::string errors_;
};

// ---- limits (claw_limits.hpp) ---------------------------------------------

// urdfdom turns every rpy into a quaternion (any angle gives a valid one):
// the angles are checked in the text, each rpy="r p y" attribute, before it
// is parsed. Values that are not three numbers are left to urdfdom.
void CheckUrdfAngles(const std::string& label, const std::string& text) {
  for (size_t at = text.find("rpy"); at != std::string::npos; at = text.find("rpy", at + 3)) {
    if (at == 0 || !std::isspace(static_cast<unsigned char>(text[at - 1]))) continue;
    size_t i = text.find_first_not_of(" \t\r\n", at + 3);
    if (i == std::string::npos || text[i] != '=') continue;
    i = text.find_first_not_of(" \t\r\n", i + 1);
    if (i == std::string::npos || (text[i] != '"' && text[i] != '\'')) continue;
    const size_t end = text.find(text[i], i + 1);
    if (end == std::string::npos) break;
    std::istringstream values(text.substr(i + 1, end - i - 1));
    double angle = 0.0;
    for (int k = 0; k < 3 && values >> angle; ++k) {
      const std::string defect = AngleDefect(angle);
      if (defect.empty()) continue;
      const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
      Fail(label, "line " + std::to_string(line) + ": rpy[" + std::to_string(k) + "]: " + defect);
    }
  }
}

// A movable joint's limits (the URDF's or the config's): meters for a
// prismatic joint, radians for a revolute one; a continuous one has none.
void CheckJointTravel(const std::string& label, const Joint& joint, const std::string& name) {
  if (!std::isfinite(joint.lower) && !std::isfinite(joint.upper)) return;  // continuous
  const auto defect = joint.type == JointType::kPrismatic ? DistanceDefect : AngleDefect;
  CheckLimit(label, "joint '" + name + "': lower limit", defect(joint.lower));
  CheckLimit(label, "joint '" + name + "': upper limit", defect(joint.upper));
}

// The whole claw, once built: no point beyond kMaxClawReachM in any pose.
ClawModel WithinReach(const std::string& label, ClawModel model) {
  if (const std::string defect = ClawReachDefect(model); !defect.empty()) Fail(label, defect);
  return model;
}

// Every link's meshes so far, against kMaxClawTriangles (each mesh file is
// read against the whole limit first, before its vertices are merged).
void CheckTriangleTotal(const std::string& label, const std::vector<Link>& links) {
  int64_t total = 0;
  for (const Link& link : links) total += static_cast<int64_t>(link.mesh.triangles.size());
  if (total > kMaxClawTriangles) {
    Fail(label, std::to_string(total) + " triangles, over the claw's limit of " +
                    std::to_string(kMaxClawTriangles) +
                    " (claw_limits.hpp; simplify the meshes, or use the collision geometry)");
  }
}

// Xacro saved as .urdf (urdfdom skips its elements, or finds no robot
// name): said when such a file fails.
std::string XacroHint(const std::string& urdf_text) {
  if (urdf_text.find("<xacro:") == std::string::npos) return "";
  return ": this is xacro, not URDF: run xacro first (xacro FILE.xacro > FILE.urdf)";
}

// No geometry of the chosen kind in any link: a claw that hides nothing.
// Xacro saved as .urdf is the usual cause (urdfdom skips its elements).
void CheckHasGeometry(const std::string& label, const std::vector<Link>& links, const UrdfClawConfig& c,
                      const urdf::ModelInterface& model) {
  for (const Link& link : links) {
    if (!link.mesh.empty()) return;
  }
  const bool collision = c.geometry == GeometryKind::kCollision;
  const char* kind = collision ? "collision" : "visual";
  std::string why = std::string("no link has <") + kind + "> geometry (" + std::to_string(links.size()) +
                    " link" + (links.size() == 1 ? "" : "s") + ", 0 triangles)";
  if (const std::string hint = XacroHint(c.urdf_text); !hint.empty()) {
    why += hint;
  } else {
    bool other = false;
    for (const auto& [name, link] : model.links_) {
      other = other || (collision ? !link->visual_array.empty() : !link->collision_array.empty());
    }
    if (other) {
      why += std::string(": it has <") + (collision ? "visual" : "collision") +
             "> geometry: a URDF claw config with \"geometry\": \"" + (collision ? "visual" : "collision") +
             "\" takes that";
    }
  }
  Fail(label, why);
}

// urdfdom's model of the config's URDF text, its angles and link count
// checked (the angles before urdfdom turns them into quaternions).
urdf::ModelInterfaceSharedPtr ParseUrdfModel(const std::string& label, const UrdfClawConfig& c) {
  CheckUrdfAngles(label, c.urdf_text);
  CapturedUrdfLog log;
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(c.urdf_text);
  if (!model) {
    Fail(label, "not a valid URDF" + (log.errors().empty() ? "" : " (" + log.errors() + ")") +
                    XacroHint(c.urdf_text));
  }
  if (const std::string defect = LinkCountDefect(static_cast<int64_t>(model->links_.size()));
      !defect.empty()) {
    Fail(label, defect);
  }
  if (!model->getRoot()) Fail(label, "URDF has no root link");
  for (const auto& [name, mapping] : c.joints) {
    if (model->joints_.count(name) == 0) Fail(label, "joints." + name + ": no such joint in the URDF");
  }
  for (const auto& [name, pose] : c.mesh_origins) {
    if (model->links_.count(name) == 0) Fail(label, "links." + name + ": no such link in the URDF");
  }
  return model;
}

// Links parents-first (depth first from the root, children in urdfdom's
// order, which is by joint name), with each one's parent's position (-1:
// the root).
void LinksParentsFirst(const urdf::LinkConstSharedPtr& root, std::vector<urdf::LinkConstSharedPtr>* order,
                       std::vector<int>* parent_of) {
  std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack = {{root, -1}};
  while (!stack.empty()) {
    auto [link, parent] = stack.back();
    stack.pop_back();
    const int index = static_cast<int>(order->size());
    order->push_back(link);
    parent_of->push_back(parent);
    for (auto it = link->child_links.rbegin(); it != link->child_links.rend(); ++it) {
      stack.emplace_back(*it, index);
    }
  }
}

// Actuated joints: movable and not mimic, by name (their default
// joint_index is their rank here).
std::vector<std::string> ActuatedJoints(const std::string& label, const UrdfClawConfig& c,
                                        const urdf::ModelInterface& model) {
  std::vector<std::string> actuated;
  for (const auto& [name, joint] : model.joints_) {
    const bool movable = joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::CONTINUOUS ||
                         joint->type == urdf::Joint::PRISMATIC;
    if (joint->type == urdf::Joint::FLOATING || joint->type == urdf::Joint::PLANAR) {
      Fail(label, "joint '" + name + "': floating and planar joints are not supported in a claw");
    }
    if (movable && !joint->mimic) actuated.push_back(name);
    if (joint->mimic && c.joints.count(name)) {
      Fail(label,
           "joints." + name + ": a mimic joint follows '" + joint->mimic->joint_name + "'; map that one");
    }
  }
  return actuated;
}

// The joint from a link's parent: its origin, type, axis and limits (the
// config's limits over the URDF's).
void ReadJoint(const std::string& label, const UrdfClawConfig& c, const urdf::Joint& j, Joint* out) {
  CheckOriginLimits(label, "joint '" + j.name + "': ", j.parent_to_joint_origin_transform);
  out->T_parent_joint = ToIsometry(j.parent_to_joint_origin_transform);
  if (j.type == urdf::Joint::FIXED) return;
  out->type = j.type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
  out->axis = Eigen::Vector3d(j.axis.x, j.axis.y, j.axis.z);
  if (!out->axis.allFinite() || !(out->axis.norm() > 1e-9)) {
    Fail(label, "joint '" + j.name + "': zero or non-finite axis");
  }
  if (j.type == urdf::Joint::CONTINUOUS) {
    out->lower = -std::numeric_limits<double>::infinity();
    out->upper = std::numeric_limits<double>::infinity();
  } else {
    if (!j.limits) Fail(label, "joint '" + j.name + "': no <limit>");
    out->lower = j.limits->lower;
    out->upper = j.limits->upper;
  }
  const auto m = c.joints.find(j.name);
  if (m != c.joints.end() && m->second.has_limits) {
    out->lower = m->second.lower;
    out->upper = m->second.upper;
  }
  CheckJointTravel(label, *out, j.name);
  if (!(out->lower <= out->upper)) Fail(label, "joint '" + j.name + "': limits lower > upper");
}

// Every link (parents first) with its geometry and the joint from its
// parent; link_of_joint: each joint's child link.
std::vector<Link> ReadLinks(const std::string& label, const UrdfClawConfig& c,
                            const urdf::ModelInterface& model, const fs::path& mesh_root,
                            std::map<std::string, int>* link_of_joint) {
  std::vector<urdf::LinkConstSharedPtr> order;
  std::vector<int> parent_of;
  LinksParentsFirst(model.getRoot(), &order, &parent_of);
  const fs::path root_dir = mesh_root.empty() && !c.confined ? c.urdf_dir : mesh_root;
  std::vector<Link> links(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const urdf::Link& in = *order[i];
    Link& out = links[i];
    out.name = in.name;
    out.parent = parent_of[i];
    ReadLinkGeometry(label, in, c, root_dir, &out);
    CheckTriangleTotal(label, links);
    if (out.parent < 0) {
      out.joint.T_parent_joint = c.T_G_root;
      continue;
    }
    (*link_of_joint)[in.parent_joint->name] = static_cast<int>(i);
    ReadJoint(label, c, *in.parent_joint, &out.joint);
  }
  return links;
}

ClawModel Build(const std::string& label, const UrdfClawConfig& c, const fs::path& mesh_root) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdfModel(label, c);
  const std::vector<std::string> actuated = ActuatedJoints(label, c, *model);
  std::map<std::string, int> link_of_joint;
  std::vector<Link> links = ReadLinks(label, c, *model, mesh_root, &link_of_joint);
  CheckHasGeometry(label, links, c, *model);

  const std::string default_opening_doc = DriveJoints(label, c, *model, actuated, link_of_joint, &links);
  std::string name = c.name.empty() ? model->getName() : c.name;
  const std::string opening_doc = c.opening_doc.empty() ? default_opening_doc : c.opening_doc;
  try {
    return WithinReach(label, ClawModel(name, std::move(links), opening_doc));
  } catch (const std::invalid_argument& e) {
    Fail(label, e.what());
  }
}

json ParseJson(const std::string& label, const std::string& text) {
  try {
    json doc = json::parse(text);
    if (!doc.is_object()) Fail(label, "bad JSON: top level must be an object");
    return doc;
  } catch (const json::exception& e) {
    Fail(label, std::string("bad JSON: ") + e.what());
  }
}

// The config of `path` with the URDF's text and folder filled in.
json ConfigWithUrdf(const std::string& path, const std::string& mesh_root) {
  std::string text;
  try {
    text = ReadText(path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (claw)");
  }
  if (IsUrdfFileName(path)) {
    return json{{"urdf_text", text},
                {"urdf_dir", fs::absolute(fs::path(path)).parent_path().lexically_normal().string()}};
  }
  json doc = ParseJson(path, text);
  if (doc.contains("urdf")) {
    if (!doc["urdf"].is_string()) Fail(path, "urdf: expected a path");
    fs::path urdf = doc["urdf"].get<std::string>();
    if (urdf.is_relative()) {
      urdf = (mesh_root.empty() ? fs::path(path).parent_path() : fs::path(mesh_root)) / urdf;
    }
    try {
      doc["urdf_text"] = ReadText(urdf.string());
    } catch (const std::runtime_error& e) {
      Fail(path, std::string("urdf: ") + e.what());
    }
    doc["urdf_dir"] = fs::absolute(urdf).parent_path().lexically_normal().string();
    doc.erase("urdf");
  }
  if (!doc.contains("urdf_text")) Fail(path, "no \"urdf\" (a URDF claw config names its URDF)");
  return doc;
}

ClawModel FromConfig(const std::string& label, const json& doc, const std::string& mesh_root, bool confined) {
  UrdfClawConfig c = ParseConfig(label, doc);
  c.confined = confined;
  if (!doc.contains("urdf_text") || !doc["urdf_text"].is_string()) {
    Fail(label, "urdf_text: missing (the URDF itself)");
  }
  c.urdf_text = doc["urdf_text"].get<std::string>();
  if (doc.contains("urdf_dir")) {
    if (!doc["urdf_dir"].is_string()) Fail(label, "urdf_dir: expected a path");
    c.urdf_dir = doc["urdf_dir"].get<std::string>();
  }
  return Build(label, c, mesh_root);
}

}  // namespace

bool IsUrdfClaw(const std::string& path) {
  if (IsUrdfFileName(path)) return true;
  try {
    // Not a regular file (a FIFO): no, and the description loader says why.
    const json doc = json::parse(ReadText(path));
    return doc.is_object() && (doc.contains("urdf") || doc.contains("urdf_text"));
  } catch (const std::exception&) {
    return false;
  }
}

ClawModel LoadUrdfClaw(const std::string& path, const std::string& mesh_root) {
  return FromConfig(path, ConfigWithUrdf(path, mesh_root), mesh_root, false);
}

std::string UrdfClawBundle(const std::string& path, const std::string& mesh_root) {
  return ConfigWithUrdf(path, mesh_root).dump();
}

ClawModel LoadUrdfClawText(const std::string& config_text, const std::string& label,
                           const std::string& mesh_root) {
  const size_t first = config_text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) Fail(label, "no URDF (empty text)");
  // Another publisher may carry the URDF itself rather than a config.
  if (config_text[first] == '<') {
    return FromConfig(label, json{{"urdf_text", config_text}}, mesh_root, true);
  }
  return FromConfig(label, ParseJson(label, config_text), mesh_root, true);
}

}  // namespace graspfill::claw
