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
#include <set>
#include <sstream>
#include <stdexcept>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/claw/mesh_check.hpp"
#include "graspfill/claw/mesh_file.hpp"
#include "graspfill/claw/mesh_path.hpp"
#include "graspfill/claw/primitive_meshes.hpp"
#include "graspfill/core/regular_file.hpp"

namespace graspfill::claw {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& label, const std::string& what) {
  throw std::runtime_error(label + ": " + what);
}

// A regular file only (a FIFO would block), of at most kMaxClawFileBytes.
std::string ReadText(const std::string& path) {
  return ReadRegularFile(path, kMaxClawFileBytes, "cannot open file");
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool IsUrdfFileName(const std::string& path) {
  return Lower(fs::path(path).extension().string()) == ".urdf";
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

void CheckLimit(const std::string& label, const std::string& field, const std::string& defect) {
  if (!defect.empty()) Fail(label, field + ": " + defect);
}

void CheckEach(const std::string& label, const Eigen::Vector3d& v, const std::string& field,
               std::string (*defect)(double)) {
  for (int k = 0; k < 3; ++k) CheckLimit(label, field + "[" + std::to_string(k) + "]", defect(v[k]));
}

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

// A <box>, <cylinder>, <sphere> or <mesh scale>, before it is meshed or read.
void CheckGeometryLimits(const std::string& label, const std::string& what,
                         const urdf::Geometry& geometry) {
  switch (geometry.type) {
    case urdf::Geometry::BOX: {
      const urdf::Vector3& d = static_cast<const urdf::Box&>(geometry).dim;
      CheckEach(label, Eigen::Vector3d(d.x, d.y, d.z), what + "box size", SizeDefect);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      CheckLimit(label, what + "cylinder radius", SizeDefect(cylinder.radius));
      CheckLimit(label, what + "cylinder length", SizeDefect(cylinder.length));
      break;
    }
    case urdf::Geometry::SPHERE:
      CheckLimit(label, what + "sphere radius",
                 SizeDefect(static_cast<const urdf::Sphere&>(geometry).radius));
      break;
    case urdf::Geometry::MESH: {
      const urdf::Vector3& scale = static_cast<const urdf::Mesh&>(geometry).scale;
      for (const double v : {scale.x, scale.y, scale.z}) {
        CheckLimit(label, what + "mesh", ScaleDefect(v));
      }
      break;
    }
    default:
      break;  // refused where it is meshed
  }
}

// An element's or a joint's origin.
void CheckOriginLimits(const std::string& label, const std::string& what, const urdf::Pose& origin) {
  const urdf::Vector3& p = origin.position;
  CheckEach(label, Eigen::Vector3d(p.x, p.y, p.z), what + "origin xyz", DistanceDefect);
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

// ---- the config (JSON) -----------------------------------------------------

Eigen::Vector3d ReadVector3(const std::string& label, const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 3) Fail(label, field + ": expected an array of 3 numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number() || !std::isfinite(j[k].get<double>())) {
      Fail(label, field + "[" + std::to_string(k) + "]: expected a finite number");
    }
    v[k] = j[k].get<double>();
  }
  return v;
}

double ReadNumber(const std::string& label, const json& j, const std::string& field) {
  if (!j.is_number() || !std::isfinite(j.get<double>())) {
    Fail(label, field + ": expected a finite number");
  }
  return j.get<double>();
}

void CheckKeys(const std::string& label, const json& j, const std::string& field,
               const std::set<std::string>& allowed) {
  if (!j.is_object()) Fail(label, field + ": expected an object");
  for (const auto& [key, value] : j.items()) {
    const bool doc = key == "doc" || (key.size() > 4 && key.compare(key.size() - 4, 4, "_doc") == 0);
    if (doc || allowed.count(key)) continue;
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
    Fail(label, field + (field.empty() ? "" : ": ") + "unknown key '" + key + "' (expected " +
                    list + ")");
  }
}

Eigen::Matrix3d RotationFromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Isometry3d ReadPose(const std::string& label, const json& j, const std::string& field) {
  CheckKeys(label, j, field, {"xyz", "rpy"});
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (j.contains("xyz")) {
    T.translation() = ReadVector3(label, j["xyz"], field + ".xyz");
    CheckEach(label, T.translation(), field + ".xyz", DistanceDefect);
  }
  if (j.contains("rpy")) {
    const Eigen::Vector3d rpy = ReadVector3(label, j["rpy"], field + ".rpy");
    CheckEach(label, rpy, field + ".rpy", AngleDefect);
    T.linear() = RotationFromRpy(rpy);
  }
  return T;
}

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
  fs::path urdf_dir;  ///< relative meshes, when no mesh root
  /// Text from elsewhere (a session description): meshes only under the
  /// local mesh root (mesh_path.hpp), urdf_dir never read.
  bool confined{false};
};

UrdfClawConfig ParseConfig(const std::string& label, const json& doc) {
  CheckKeys(label, doc, "",
            {"name", "opening_doc", "urdf", "urdf_text", "urdf_dir", "geometry", "T_G_root",
             "joints", "links", "source", "mesh_root_hint"});
  UrdfClawConfig c;
  if (doc.contains("name")) {
    if (!doc["name"].is_string()) Fail(label, "name: expected a string");
    c.name = doc["name"].get<std::string>();
  }
  if (doc.contains("opening_doc")) {
    if (!doc["opening_doc"].is_string()) Fail(label, "opening_doc: expected a string");
    c.opening_doc = doc["opening_doc"].get<std::string>();
  }
  if (doc.contains("T_G_root")) c.T_G_root = ReadPose(label, doc["T_G_root"], "T_G_root");
  if (doc.contains("geometry")) {
    const json& g = doc["geometry"];
    if (g == "collision") {
      c.geometry = GeometryKind::kCollision;
    } else if (g == "visual") {
      c.geometry = GeometryKind::kVisual;
    } else {
      Fail(label, "geometry: expected \"collision\" or \"visual\"");
    }
  }
  if (doc.contains("joints") && !doc["joints"].is_object()) {
    Fail(label, "joints: expected an object {joint name: {open, closed, limits, joint_index}}");
  }
  if (const auto it = doc.find("joints"); it != doc.end()) {
    for (const auto& [name, j] : it->items()) {
      const std::string field = "joints." + name;
      CheckKeys(label, j, field, {"open", "closed", "limits", "joint_index"});
      JointMapping m;
      if (j.contains("open") != j.contains("closed")) {
        Fail(label, field + ": give both open and closed (equal values hold the joint)");
      }
      if (j.contains("open")) {
        m.has_open_closed = true;
        m.open = ReadNumber(label, j["open"], field + ".open");
        m.closed = ReadNumber(label, j["closed"], field + ".closed");
      }
      if (j.contains("limits")) {
        CheckKeys(label, j["limits"], field + ".limits", {"lower", "upper"});
        if (!j["limits"].contains("lower") || !j["limits"].contains("upper")) {
          Fail(label, field + ".limits: expected {lower, upper}");
        }
        m.has_limits = true;
        m.lower = ReadNumber(label, j["limits"]["lower"], field + ".limits.lower");
        m.upper = ReadNumber(label, j["limits"]["upper"], field + ".limits.upper");
        if (m.lower > m.upper) Fail(label, field + ".limits: lower > upper");
      }
      if (j.contains("joint_index")) {
        if (!j["joint_index"].is_number_integer() || j["joint_index"].get<int64_t>() < 0 ||
            j["joint_index"].get<int64_t>() >= kMaxClawLinks) {
          Fail(label, field + ".joint_index: expected an integer 0.." +
                          std::to_string(kMaxClawLinks - 1) + " (one per joint; claw_limits.hpp)");
        }
        m.joint_index = j["joint_index"].get<int>();
      }
      c.joints[name] = m;
    }
  }
  if (const auto it = doc.find("links"); it != doc.end()) {
    if (!it->is_object()) Fail(label, "links: expected an object {link name: {mesh_origin}}");
    for (const auto& [name, j] : it->items()) {
      CheckKeys(label, j, "links." + name, {"mesh_origin"});
      if (j.contains("mesh_origin")) {
        c.mesh_origins[name] = ReadPose(label, j["mesh_origin"], "links." + name + ".mesh_origin");
      }
    }
  }
  return c;
}

// ---- meshes ----------------------------------------------------------------

// `package://PKG/a/b/file`: ROS would ask the package index; here the first
// of root/PKG/a/b/file, root/a/b/file, root/b/file, root/file that exists.
// Confined (text from elsewhere): every candidate inside root, none absolute
// (file://) or with a '..' part.
fs::path ResolveMesh(const std::string& label, const std::string& link, const std::string& uri,
                     const fs::path& root, bool confined) {
  std::string path = uri;
  const std::string kPackage = "package://";
  const std::string kFile = "file://";
  if (path.compare(0, kFile.size(), kFile) == 0) path = path.substr(kFile.size());
  const bool package = path.compare(0, kPackage.size(), kPackage) == 0;
  if (confined) {
    try {
      ConfinedMeshPath(root.string(), package ? path.substr(kPackage.size()) : path);
    } catch (const std::runtime_error& e) {
      Fail(label, "link '" + link + "': " + e.what());
    }
  }
  if (package) {
    const fs::path rest = path.substr(kPackage.size());
    std::vector<fs::path> parts(rest.begin(), rest.end());
    for (size_t first = 0; first < parts.size(); ++first) {
      fs::path candidate = root;
      for (size_t k = first; k < parts.size(); ++k) candidate /= parts[k];
      std::error_code ec;
      if (fs::is_regular_file(candidate, ec)) return candidate;
    }
    Fail(label, "link '" + link + "': mesh '" + uri + "' not found under " + root.string() +
                    " (tried every trailing part of the path; pass the folder holding it as "
                    "the mesh root)");
  }
  const fs::path p(path);
  return p.is_absolute() ? p : root / p;
}

// A mesh file's triangles, scaled, checked and without zero-area ones
// (counted in *dropped).
TriangleMesh ReadUrdfMesh(const std::string& label, const std::string& what,
                          const std::string& link, const urdf::Mesh& m, const fs::path& root,
                          bool confined, int* dropped) {
  const fs::path file = ResolveMesh(label, link, m.filename, root, confined);
  TriangleMesh mesh;
  try {
    mesh = ReadMeshFile(file.string());
  } catch (const std::runtime_error& e) {
    Fail(label, what + "mesh: " + e.what());
  }
  if (const std::string defect = MeshDefect(mesh); !defect.empty()) {
    Fail(label, what + "mesh: " + file.string() + ": " + defect);
  }
  const Eigen::Vector3f scale(static_cast<float>(m.scale.x), static_cast<float>(m.scale.y),
                              static_cast<float>(m.scale.z));
  if (!scale.allFinite() || !(scale.array() > 0.0f).all()) {
    Fail(label, what + "mesh: " + m.filename + ": scale must be positive");
  }
  for (Eigen::Vector3f& v : mesh.vertices) v = v.cwiseProduct(scale);
  *dropped += DropDegenerateTriangles(&mesh);
  if (mesh.empty()) Fail(label, what + "mesh: " + file.string() + ": every triangle has zero area");
  return mesh;
}

// One <collision> or <visual> element's geometry as triangles, in its own
// frame, checked.
TriangleMesh ElementMesh(const std::string& label, const std::string& what,
                         const std::string& link, const urdf::Geometry& geometry,
                         const fs::path& root, bool confined, int* dropped) {
  CheckGeometryLimits(label, what, geometry);
  TriangleMesh mesh;
  switch (geometry.type) {
    case urdf::Geometry::MESH:
      mesh = ReadUrdfMesh(label, what, link, static_cast<const urdf::Mesh&>(geometry), root,
                          confined, dropped);
      break;
    case urdf::Geometry::BOX: {
      const urdf::Vector3& dim = static_cast<const urdf::Box&>(geometry).dim;
      mesh = BoxMesh(Eigen::Vector3d(dim.x, dim.y, dim.z));
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cyl = static_cast<const urdf::Cylinder&>(geometry);
      mesh = CylinderMesh(cyl.radius, cyl.length);
      break;
    }
    case urdf::Geometry::SPHERE:
      mesh = SphereMesh(static_cast<const urdf::Sphere&>(geometry).radius);
      break;
    default:
      Fail(label, what + "geometry of an unknown type");
  }
  if (const std::string defect = MeshDefect(mesh); !defect.empty()) {
    Fail(label, what + "geometry: " + defect);
  }
  CheckLimit(label, what + "geometry", MeshExtentDefect(mesh));
  return mesh;
}

Eigen::Isometry3d ToIsometry(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return T;
}

// The link's geometry of the chosen kind in the link frame (several
// elements are merged); T_link_mesh is the single element's origin.
void ReadLinkGeometry(const std::string& label, const urdf::Link& in, const UrdfClawConfig& c,
                      const fs::path& root, Link* out) {
  std::vector<std::pair<urdf::Pose, urdf::GeometrySharedPtr>> elements;
  const char* kind = c.geometry == GeometryKind::kCollision ? "collision" : "visual";
  if (c.geometry == GeometryKind::kCollision) {
    for (const auto& e : in.collision_array) {
      if (e && e->geometry) elements.emplace_back(e->origin, e->geometry);
    }
  } else {
    for (const auto& e : in.visual_array) {
      if (e && e->geometry) elements.emplace_back(e->origin, e->geometry);
    }
  }
  const auto override_it = c.mesh_origins.find(in.name);
  if (override_it != c.mesh_origins.end() && elements.size() != 1) {
    Fail(label, "links." + in.name + ".mesh_origin: the link has " +
                    std::to_string(elements.size()) + " " + kind +
                    " elements (an override needs exactly one)");
  }
  for (const auto& [origin, geometry] : elements) {
    const std::string what = std::string("link '") + in.name + "': " + kind + " ";
    TriangleMesh mesh = ElementMesh(label, what, in.name, *geometry, root, c.confined,
                                    &out->degenerate_triangles_dropped);
    CheckOriginLimits(label, what, origin);
    const Eigen::Isometry3d T =
        override_it != c.mesh_origins.end() ? override_it->second : ToIsometry(origin);
    if (elements.size() == 1) {
      out->T_link_mesh = T;
      out->mesh = std::move(mesh);
    } else {
      out->mesh.Append(mesh.Transformed(T));
    }
  }
}

// ---- kinematics and the opening --------------------------------------------

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

// Xacro saved as .urdf (urdfdom skips its elements, or finds no robot
// name): said when such a file fails.
std::string XacroHint(const std::string& urdf_text) {
  if (urdf_text.find("<xacro:") == std::string::npos) return "";
  return ": this is xacro, not URDF: run xacro first (xacro FILE.xacro > FILE.urdf)";
}

// No geometry of the chosen kind in any link: a claw that hides nothing.
// Xacro saved as .urdf is the usual cause (urdfdom skips its elements).
void CheckHasGeometry(const std::string& label, const std::vector<Link>& links,
                      const UrdfClawConfig& c, const urdf::ModelInterface& model) {
  for (const Link& link : links) {
    if (!link.mesh.empty()) return;
  }
  const bool collision = c.geometry == GeometryKind::kCollision;
  const char* kind = collision ? "collision" : "visual";
  std::string why = std::string("no link has <") + kind + "> geometry (" +
                    std::to_string(links.size()) + " link" + (links.size() == 1 ? "" : "s") +
                    ", 0 triangles)";
  if (const std::string hint = XacroHint(c.urdf_text); !hint.empty()) {
    why += hint;
  } else {
    bool other = false;
    for (const auto& [name, link] : model.links_) {
      other = other || (collision ? !link->visual_array.empty() : !link->collision_array.empty());
    }
    if (other) {
      why += std::string(": it has <") + (collision ? "visual" : "collision") +
             "> geometry: a URDF claw config with \"geometry\": \"" +
             (collision ? "visual" : "collision") + "\" takes that";
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
void LinksParentsFirst(const urdf::LinkConstSharedPtr& root,
                       std::vector<urdf::LinkConstSharedPtr>* order, std::vector<int>* parent_of) {
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
    const bool movable = joint->type == urdf::Joint::REVOLUTE ||
                         joint->type == urdf::Joint::CONTINUOUS ||
                         joint->type == urdf::Joint::PRISMATIC;
    if (joint->type == urdf::Joint::FLOATING || joint->type == urdf::Joint::PLANAR) {
      Fail(label, "joint '" + name + "': floating and planar joints are not supported in a claw");
    }
    if (movable && !joint->mimic) actuated.push_back(name);
    if (joint->mimic && c.joints.count(name)) {
      Fail(label, "joints." + name + ": a mimic joint follows '" + joint->mimic->joint_name +
                      "'; map that one");
    }
  }
  return actuated;
}

// The joint from a link's parent: its origin, type, axis and limits (the
// config's limits over the URDF's).
void ReadJoint(const std::string& label, const UrdfClawConfig& c, const urdf::Joint& j,
               Joint* out) {
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
            msg << "joints." << name << ": " << q << " outside the joint's limits [" << joint.lower
                << ", " << joint.upper << "] (give limits to override the URDF's)";
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
      Fail(label, "joints: joint_index " + std::to_string(d.index) + " is both '" + it->second +
                      "' and '" + name + "' (give every actuated joint its own)");
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

MimicChain MasterOf(const std::string& label, const urdf::ModelInterface& model,
                    const std::string& name) {
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
std::map<std::string, std::vector<int>> MovedLinks(
    const std::string& label, const urdf::ModelInterface& model, const std::vector<Link>& links,
    const std::vector<std::vector<int>>& children, const std::map<std::string, int>& link_of_joint,
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
                 const std::map<std::string, int>& link_of_joint,
                 const std::map<std::string, Drive>& drives, std::vector<Link>* links) {
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
void OrientDrives(const std::string& label, const urdf::ModelInterface& model,
                  const std::vector<Link>& links, const std::vector<std::vector<int>>& children,
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
         "between; mimic joints follow. joint_values order: [" + order_text + "]";
}

ClawModel Build(const std::string& label, const UrdfClawConfig& c, const fs::path& mesh_root) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdfModel(label, c);
  const std::vector<std::string> actuated = ActuatedJoints(label, c, *model);
  std::map<std::string, int> link_of_joint;
  std::vector<Link> links = ReadLinks(label, c, *model, mesh_root, &link_of_joint);
  CheckHasGeometry(label, links, c, *model);

  std::map<std::string, Drive> drives = InitialDrives(label, c, actuated, links, link_of_joint);
  const std::vector<std::vector<int>> children = ChildrenOf(links);
  const std::map<std::string, std::vector<int>> moved =
      MovedLinks(label, *model, links, children, link_of_joint, drives);
  ApplyDrives(label, *model, link_of_joint, drives, &links);
  int max_index = 0;
  for (const auto& [name, d] : drives) max_index = std::max(max_index, d.index);
  OrientDrives(label, *model, links, children, moved, max_index, &drives);
  ApplyDrives(label, *model, link_of_joint, drives, &links);

  std::string name = c.name.empty() ? model->getName() : c.name;
  const std::string opening_doc =
      c.opening_doc.empty() ? DefaultOpeningDoc(drives, max_index) : c.opening_doc;
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

ClawModel FromConfig(const std::string& label, const json& doc, const std::string& mesh_root,
                     bool confined) {
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
