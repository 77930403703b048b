// SPDX-License-Identifier: BSD-3-Clause
// A URDF claw's config (JSON): the root pose, the geometry kind, the
// joints' mapping and the links' mesh origins, every field checked.
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>

#include "graspfill/claw/claw_limits.hpp"
#include "rpy_rotation.hpp"
#include "urdf_claw_parts.hpp"

namespace graspfill::claw::urdf_parts {

using nlohmann::json;

[[noreturn]] void Fail(const std::string& label, const std::string& what) {
  throw std::runtime_error(label + ": " + what);
}

void CheckLimit(const std::string& label, const std::string& field, const std::string& defect) {
  if (!defect.empty()) Fail(label, field + ": " + defect);
}

void CheckEach(const std::string& label, const Eigen::Vector3d& v, const std::string& field,
               std::string (*defect)(double)) {
  for (int k = 0; k < 3; ++k) CheckLimit(label, field + "[" + std::to_string(k) + "]", defect(v[k]));
}

namespace {

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
    Fail(label, field + (field.empty() ? "" : ": ") + "unknown key '" + key + "' (expected " + list + ")");
  }
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

}  // namespace

UrdfClawConfig ParseConfig(const std::string& label, const json& doc) {
  CheckKeys(label, doc, "",
            {"name", "opening_doc", "urdf", "urdf_text", "urdf_dir", "geometry", "T_G_root", "joints",
             "links", "source", "mesh_root_hint"});
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
          Fail(label, field + ".joint_index: expected an integer 0.." + std::to_string(kMaxClawLinks - 1) +
                          " (one per joint; claw_limits.hpp)");
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

}  // namespace graspfill::claw::urdf_parts
