// SPDX-License-Identifier: BSD-3-Clause
// A URDF claw's link geometry: each <collision> or <visual> element meshed
// (mesh files found under the mesh root, primitives built), checked
// against the claw's limits, and merged in the link frame.
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/claw/mesh_check.hpp"
#include "graspfill/claw/mesh_file.hpp"
#include "graspfill/claw/mesh_path.hpp"
#include "graspfill/claw/primitive_meshes.hpp"
#include "urdf_claw_parts.hpp"

namespace graspfill::claw::urdf_parts {

namespace fs = std::filesystem;

// An element's or a joint's origin.
void CheckOriginLimits(const std::string& label, const std::string& what, const urdf::Pose& origin) {
  const urdf::Vector3& p = origin.position;
  CheckEach(label, Eigen::Vector3d(p.x, p.y, p.z), what + "origin xyz", DistanceDefect);
}

Eigen::Isometry3d ToIsometry(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return T;
}

namespace {

// A <box>, <cylinder>, <sphere> or <mesh scale>, before it is meshed or read.
void CheckGeometryLimits(const std::string& label, const std::string& what, const urdf::Geometry& geometry) {
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
TriangleMesh ReadUrdfMesh(const std::string& label, const std::string& what, const std::string& link,
                          const urdf::Mesh& m, const fs::path& root, bool confined, int* dropped) {
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
TriangleMesh ElementMesh(const std::string& label, const std::string& what, const std::string& link,
                         const urdf::Geometry& geometry, const fs::path& root, bool confined, int* dropped) {
  CheckGeometryLimits(label, what, geometry);
  TriangleMesh mesh;
  switch (geometry.type) {
    case urdf::Geometry::MESH:
      mesh =
          ReadUrdfMesh(label, what, link, static_cast<const urdf::Mesh&>(geometry), root, confined, dropped);
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

}  // namespace

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
    Fail(label, "links." + in.name + ".mesh_origin: the link has " + std::to_string(elements.size()) + " " +
                    kind + " elements (an override needs exactly one)");
  }
  for (const auto& [origin, geometry] : elements) {
    const std::string what = std::string("link '") + in.name + "': " + kind + " ";
    TriangleMesh mesh =
        ElementMesh(label, what, in.name, *geometry, root, c.confined, &out->degenerate_triangles_dropped);
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

}  // namespace graspfill::claw::urdf_parts
