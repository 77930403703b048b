// SPDX-License-Identifier: BSD-3-Clause
#include "object_manifest.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace graspfill::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

// Keys starting with '_' are comments (the set's "_about").
bool IsComment(const std::string& key) { return !key.empty() && key[0] == '_'; }

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

std::string ObjectKindName(ObjectKind kind) {
  switch (kind) {
    case ObjectKind::kClosedSymmetric:
      return "closed_symmetric";
    case ObjectKind::kClosedAsymmetric:
      return "closed_asymmetric";
    case ObjectKind::kOpen:
      return "open";
  }
  return "unknown";
}

std::optional<ObjectKind> ParseObjectKind(const std::string& name) {
  for (ObjectKind k : {ObjectKind::kClosedSymmetric, ObjectKind::kClosedAsymmetric, ObjectKind::kOpen}) {
    if (ObjectKindName(k) == name) return k;
  }
  return std::nullopt;
}

std::string ObjectSplitName(ObjectSplit split) { return split == ObjectSplit::kTune ? "tune" : "check"; }

std::optional<ObjectSplit> ParseObjectSplit(const std::string& name) {
  if (name == "tune") return ObjectSplit::kTune;
  if (name == "check") return ObjectSplit::kCheck;
  return std::nullopt;
}

std::string ManifestPath(const std::string& dir) { return (fs::path(dir) / "objects.json").string(); }

std::vector<ManifestObject> ReadObjectManifest(const std::string& dir) {
  const std::string path = ManifestPath(dir);
  auto fail = [&](const std::string& what) { throw ManifestError(path + ": " + what); };
  if (!fs::is_directory(dir)) throw ManifestError("'" + dir + "' is not a directory");
  if (!fs::is_regular_file(path)) fail("not found (the objects of the set: see `bench repair --help`)");
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) fail("cannot be read");
  ordered_json manifest;
  try {
    manifest = ordered_json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    fail(std::string("not valid JSON: ") + e.what());
  }
  if (!manifest.is_object()) fail("expected a JSON object with \"objects\"");
  for (const auto& [key, value] : manifest.items()) {
    if (key != "objects" && !IsComment(key)) fail("unknown key " + Quoted(key) + " (expected \"objects\")");
  }
  if (!manifest.contains("objects")) fail("no \"objects\"");
  const ordered_json& objects = manifest["objects"];
  if (!objects.is_object() || objects.empty()) {
    fail("\"objects\" must be a non-empty object of name: {\"file\", \"kind\", \"split\"}");
  }
  std::vector<ManifestObject> out;
  for (const auto& [name, entry] : objects.items()) {
    if (IsComment(name)) continue;
    const std::string where = "object " + Quoted(name);
    if (name.empty()) fail("an object with an empty name");
    if (!entry.is_object()) fail(where + ": expected {\"file\", \"kind\", \"split\"}");
    for (const auto& [key, value] : entry.items()) {
      if (key != "file" && key != "kind" && key != "split" && key != "mesh_scale" && key != "mesh_up" &&
          !IsComment(key)) {
        fail(where + ": unknown key " + Quoted(key) + " (file, kind, split, mesh_scale, mesh_up)");
      }
    }
    auto text_field = [&](const char* key) {
      if (!entry.contains(key)) fail(where + ": no \"" + key + "\"");
      if (!entry[key].is_string()) fail(where + ": \"" + key + "\" must be a string");
      return entry[key].get<std::string>();
    };
    ManifestObject o;
    o.name = name;
    const std::string file = text_field("file");
    if (file.empty()) fail(where + ": \"file\" is empty");
    o.path = (fs::path(dir) / file).string();
    const std::string kind = text_field("kind");
    const std::optional<ObjectKind> k = ParseObjectKind(kind);
    if (!k) fail(where + ": unknown kind " + Quoted(kind) + " (closed_symmetric, closed_asymmetric or open)");
    o.kind = *k;
    const std::string split = text_field("split");
    const std::optional<ObjectSplit> s = ParseObjectSplit(split);
    if (!s) fail(where + ": unknown split " + Quoted(split) + " (tune or check)");
    o.split = *s;
    if (entry.contains("mesh_scale")) {
      const ordered_json& scale = entry["mesh_scale"];
      if (!scale.is_number() || !std::isfinite(scale.get<double>()) || scale.get<double>() < 1e-6 ||
          scale.get<double>() > 1e6) {
        fail(where + ": \"mesh_scale\" must be a number in 1e-6..1e6 (0.001: a mesh in mm)");
      }
      o.mesh_scale = scale.get<double>();
    }
    if (entry.contains("mesh_up")) {
      const std::string up = text_field("mesh_up");
      if (up != "z" && up != "y") fail(where + ": \"mesh_up\" must be \"z\" or \"y\", not " + Quoted(up));
      o.mesh_y_up = up == "y";
    }
    if (!fs::is_regular_file(o.path)) fail(where + ": mesh " + Quoted(o.path) + " not found");
    out.push_back(std::move(o));
  }
  if (out.empty()) fail("\"objects\" lists no object");
  return out;
}

}  // namespace graspfill::cli
