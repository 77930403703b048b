// SPDX-License-Identifier: BSD-3-Clause
// DIR/objects.json: a set of object meshes for `bench repair --objects`,
// each with the kind that decides which targets its repair must meet and
// the split it belongs to (tune on one, confirm on the other).
//
//   {"_about": "...",                       keys starting with '_': comments
//    "objects": {
//      "058_golf_ball": {"file": "058_golf_ball.ply",    relative to DIR
//                        "kind": "closed_symmetric",      or closed_asymmetric, open
//                        "split": "tune",                 or check
//                        "mesh_scale": 1.0,               optional: into meters (0.001: mm)
//                        "mesh_up": "z"},                 optional: z or y (turned onto +z)
//      ...}}
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace graspfill::cli {

/// closed_symmetric: closed and roughly mirror- or rotation-symmetric, the
/// model must come out complete and right; closed_asymmetric: closed, no
/// usable symmetry; open: an opening, a handle or a free form, the repair
/// must add nothing wrong.
enum class ObjectKind { kClosedSymmetric, kClosedAsymmetric, kOpen };
enum class ObjectSplit { kTune, kCheck };

std::string ObjectKindName(ObjectKind kind);
std::optional<ObjectKind> ParseObjectKind(const std::string& name);
std::string ObjectSplitName(ObjectSplit split);
std::optional<ObjectSplit> ParseObjectSplit(const std::string& name);

struct ManifestObject {
  std::string name;  ///< the key in "objects"
  std::string path;  ///< the mesh file: DIR / "file"
  ObjectKind kind{ObjectKind::kClosedSymmetric};
  ObjectSplit split{ObjectSplit::kTune};
  double mesh_scale{1.0};
  bool mesh_y_up{false};
};

/// A manifest that cannot be used; the message names the file.
class ManifestError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The path of DIR's manifest.
std::string ManifestPath(const std::string& dir);

/// The objects of DIR/objects.json in the file's order, every listed mesh
/// file checked to exist (not read).
/// @throws ManifestError on a missing folder or file, bad JSON, a missing
///   or mistyped field, an unknown key, kind or split, a missing mesh.
std::vector<ManifestObject> ReadObjectManifest(const std::string& dir);

}  // namespace graspfill::cli
