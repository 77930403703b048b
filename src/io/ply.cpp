// SPDX-License-Identifier: BSD-3-Clause
// PLY and mesh files. Writers are hand-written (see ply.hpp for why) and emit
// little-endian bytes explicitly, so output does not depend on the host.
// PLY is read by our own parser (ply_parser.hpp: checked before anything is
// allocated); other mesh formats (STL, OBJ) through Open3D.
#include "graspfill/io/ply.hpp"

#include "cloud_encoding.hpp"
#include "graspfill/core/provenance_colors.hpp"
#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/messages.hpp"
#include "ply_parser.hpp"

#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace graspfill::io {
namespace {

// Bounds reading a header by hand, so a file that is not PLY is not read
// whole looking for "end_header".
constexpr int kMaxHeaderLines = 256;

[[noreturn]] void Fail(const std::string& what, const std::string& path, const std::string& why) {
  throw std::runtime_error(what + " '" + path + "': " + why);
}

// Atomically: a failed write (full disk) never replaces a good file.
void WriteFile(const std::string& what, const std::string& path, const std::string& bytes,
               IfExists if_exists) {
  WriteFileAtomically(path, bytes, what, if_exists);
}

void CheckReadable(const std::string& what, const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) Fail(what, path, "no such file");
  if (std::filesystem::is_directory(path, ec)) {
    Fail(what, path, "is a directory");
  }
}

// Reads WriteCloudPly's header comments ("comment graspfill <key> <value>")
// into *cloud; other comments and properties are left to Open3D.
void ReadHeaderComments(const std::string& path, ObjectCloud* cloud) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail("cannot read PLY", path, std::strerror(errno));
  std::string line;
  const std::string prefix = "comment graspfill ";
  for (int n = 0; n < kMaxHeaderLines && std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") return;
    if (line.compare(0, prefix.size(), prefix) != 0) continue;
    std::istringstream fields(line.substr(prefix.size()));
    std::string key;
    fields >> key;
    bool ok = true;
    if (key == "frame_name") {
      fields >> std::ws;
      std::getline(fields, cloud->frame_name);
    } else if (key == "utime") {
      ok = static_cast<bool>(fields >> cloud->utime);
    } else if (key == "seq") {
      ok = static_cast<bool>(fields >> cloud->seq);
    } else if (key == "T_C_G") {
      double t[3], q[4];
      ok = static_cast<bool>(fields >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >> q[2] >> q[3]);
      Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
      ok = ok && std::isfinite(rotation.norm()) && std::abs(rotation.norm() - 1.0) < 1e-3 &&
           std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2]);
      if (ok) {
        cloud->T_C_G.setIdentity();
        cloud->T_C_G.linear() = rotation.normalized().toRotationMatrix();
        cloud->T_C_G.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
      }
    }
    if (!ok) Fail("cannot read PLY", path, "malformed comment '" + line + "'");
  }
  // No end_header within bounds: Open3D will report the malformed header.
}

}  // namespace

void WriteCloudPly(const std::string& path, const ObjectCloud& cloud, IfExists if_exists) {
  CheckOnePerPoint(cloud, "cannot write PLY", path);
  const size_t n = cloud.points_G.size();
  const bool has_normals = !cloud.normals_G.empty();
  const bool has_confidence = !cloud.confidence.empty();
  // Header comments must stay on one line each.
  const std::string frame_name = OneLine(cloud.frame_name);
  Eigen::Quaterniond q(cloud.T_C_G.rotation());
  q.normalize();
  const Eigen::Vector3d& t = cloud.T_C_G.translation();

  std::string bytes;
  bytes.reserve(640 + n * (16 + (has_normals ? 12 : 0) + (has_confidence ? 4 : 0)));
  bytes += "ply\nformat binary_little_endian 1.0\n";
  bytes += "comment graspfill object cloud, gripper frame G, meters\n";
  // The version only (no date): the same cloud must give the same bytes.
  bytes += "comment graspfill software " + SoftwareVersion() + "\n";
  bytes += "comment graspfill frame_name " + frame_name + "\n";
  bytes += "comment graspfill utime " + std::to_string(cloud.utime) + "\n";
  bytes += "comment graspfill seq " + std::to_string(cloud.seq) + "\n";
  bytes += "comment graspfill T_C_G " + FormatDouble(t.x()) + " " + FormatDouble(t.y()) + " " +
           FormatDouble(t.z()) + " " + FormatDouble(q.w()) + " " + FormatDouble(q.x()) + " " +
           FormatDouble(q.y()) + " " + FormatDouble(q.z()) + "\n";
  bytes += "comment provenance: 0 observed, 1 surface repair, 2 symmetry\n";
  bytes += "comment red green blue: the provenance's colour, for viewers\n";
  bytes += "element vertex " + std::to_string(n) + "\n";
  bytes += "property float x\nproperty float y\nproperty float z\n";
  if (has_normals) {
    bytes += "property float nx\nproperty float ny\nproperty float nz\n";
  }
  bytes += "property uchar provenance\n";
  if (has_confidence) bytes += "property float confidence\n";
  bytes += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  bytes += "end_header\n";
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.points_G[i][k]);
    if (has_normals) {
      for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.normals_G[i][k]);
    }
    const Provenance p = cloud.provenance.empty() ? Provenance::kObserved : cloud.provenance[i];
    bytes.push_back(static_cast<char>(p));
    if (has_confidence) AppendFloat(&bytes, cloud.confidence[i]);
    for (const uint8_t c : ProvenanceColor(p)) bytes.push_back(static_cast<char>(c));
  }
  WriteFile("cannot write PLY", path, bytes, if_exists);
}

ObjectCloud ReadCloudPly(const std::string& path) {
  const std::string what = "cannot read PLY";
  const std::string bytes = ply::ReadWholeFile(path, what);
  // Our own parser, not Open3D's: it checks the header and the body before
  // it allocates (see ply_parser.hpp).
  const ply::Parsed parsed = ply::Parse(bytes, path, what, /*want_faces=*/false);
  ObjectCloud cloud;
  ReadHeaderComments(path, &cloud);
  const size_t n = static_cast<size_t>(parsed.num_vertices);
  auto column = [&](const char* name) -> const std::vector<double>* {
    const auto it = parsed.vertex.find(name);
    return it == parsed.vertex.end() ? nullptr : &it->second;
  };
  auto to_float = [&](const char* name, size_t i, double v) {
    const float f = static_cast<float>(v);
    if (!std::isfinite(f)) {
      Fail(what, path,
           "vertex " + std::to_string(i) + ", property '" + name + "': " + FormatDouble(v) +
               " is not a finite float");
    }
    return f;
  };
  const std::vector<double>* xyz[3] = {column("x"), column("y"), column("z")};
  cloud.points_G.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      cloud.points_G[i][k] = to_float(k == 0 ? "x" : k == 1 ? "y" : "z", i, (*xyz[k])[i]);
    }
  }
  const std::vector<double>* normals[3] = {column("nx"), column("ny"), column("nz")};
  const int num_normal_columns = (normals[0] != nullptr) + (normals[1] != nullptr) + (normals[2] != nullptr);
  if (num_normal_columns != 0 && num_normal_columns != 3) {
    Fail(what, path, "normals need all of nx, ny, nz");
  }
  if (num_normal_columns == 3 && n > 0) {
    cloud.normals_G.resize(n);
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        cloud.normals_G[i][k] = to_float(k == 0 ? "nx" : k == 1 ? "ny" : "nz", i, (*normals[k])[i]);
      }
    }
  }
  if (n == 0) return cloud;
  cloud.provenance.assign(n, Provenance::kObserved);
  if (const std::vector<double>* p = column("provenance")) {
    // Other tools may have stored it as float or int; accept exact 0..2.
    for (size_t i = 0; i < n; ++i) {
      const double v = (*p)[i];
      if (v != 0.0 && v != 1.0 && v != 2.0) {
        Fail(what, path,
             "provenance value " + FormatDouble(v) + " at vertex " + std::to_string(i) + " is not 0, 1 or 2");
      }
      cloud.provenance[i] = static_cast<Provenance>(static_cast<int>(v));
    }
  }
  if (const std::vector<double>* c = column("confidence")) {
    cloud.confidence.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const float v = static_cast<float>((*c)[i]);
      if (!(v >= 0.0f && v <= 1.0f)) {
        Fail(what, path,
             "confidence value " + FormatDouble(v) + " at vertex " + std::to_string(i) + " is not in [0, 1]");
      }
      cloud.confidence[i] = v;
    }
  }
  return cloud;
}

void WriteMeshPly(const std::string& path, const TriangleMesh& mesh, IfExists if_exists) {
  const int64_t num_vertices = static_cast<int64_t>(mesh.vertices.size());
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= num_vertices) {
        Fail("cannot write PLY", path, "triangle index " + std::to_string(tri[k]) + " out of range");
      }
    }
  }
  std::string bytes;
  bytes.reserve(256 + mesh.vertices.size() * 12 + mesh.triangles.size() * 13);
  bytes += "ply\nformat binary_little_endian 1.0\n";
  bytes += "comment graspfill mesh\n";
  bytes += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  bytes += "property float x\nproperty float y\nproperty float z\n";
  bytes += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  bytes += "property list uchar int vertex_indices\nend_header\n";
  for (const Eigen::Vector3f& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) AppendFloat(&bytes, v[k]);
  }
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    bytes.push_back(3);
    for (int k = 0; k < 3; ++k) AppendInt32(&bytes, tri[k]);
  }
  WriteFile("cannot write PLY", path, bytes, if_exists);
}

namespace {

bool HasPlyExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".ply";
}

// The faces, fan-triangulated; faces with a repeated index dropped (the
// parser checked every index against the vertex count).
std::vector<Eigen::Vector3i> FanTriangles(const ply::Parsed& parsed) {
  std::vector<Eigen::Vector3i> triangles;
  for (size_t f = 0; f + 1 < parsed.face_start.size(); ++f) {
    const int64_t* idx = parsed.face_indices.data() + parsed.face_start[f];
    const int64_t count = parsed.face_start[f + 1] - parsed.face_start[f];
    for (int64_t k = 1; k + 1 < count; ++k) {
      const Eigen::Vector3i tri(static_cast<int>(idx[0]), static_cast<int>(idx[k]),
                                static_cast<int>(idx[k + 1]));
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
      triangles.push_back(tri);
    }
  }
  return triangles;
}

// PLY meshes through our parser: Open3D's reader crashed on malformed
// headers and in its ear clipping of polygons. Polygons are fan-triangulated;
// faces that repeat a vertex (degenerate) are dropped.
TriangleMesh ReadPlyMesh(const std::string& path) {
  const std::string what = "cannot read mesh";
  const std::string bytes = ply::ReadWholeFile(path, what);
  const ply::Parsed parsed = ply::Parse(bytes, path, what, /*want_faces=*/true);
  if (parsed.num_vertices > std::numeric_limits<int>::max()) {
    Fail(what, path, "too many vertices");
  }
  TriangleMesh mesh;
  const auto& x = parsed.vertex.at("x");
  const auto& y = parsed.vertex.at("y");
  const auto& z = parsed.vertex.at("z");
  mesh.vertices.resize(static_cast<size_t>(parsed.num_vertices));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f v(static_cast<float>(x[i]), static_cast<float>(y[i]), static_cast<float>(z[i]));
    if (!v.allFinite()) {
      Fail(what, path, "vertex " + std::to_string(i) + " is not finite");
    }
    mesh.vertices[i] = v;
  }
  mesh.triangles = FanTriangles(parsed);
  if (mesh.triangles.empty()) Fail(what, path, "mesh has no (non-degenerate) triangles");
  return mesh;
}

}  // namespace

std::vector<Eigen::Vector3i> ReadPlyTriangles(const std::string& path) {
  const std::string what = "cannot read PLY";
  const std::string bytes = ply::ReadWholeFile(path, what);
  const ply::Parsed parsed = ply::Parse(bytes, path, what, /*want_faces=*/true);
  if (parsed.num_vertices > std::numeric_limits<int>::max()) Fail(what, path, "too many vertices");
  return FanTriangles(parsed);
}

TriangleMesh ReadMesh(const std::string& path) {
  CheckReadable("cannot read mesh", path);
  if (HasPlyExtension(path)) return ReadPlyMesh(path);
  open3d::geometry::TriangleMesh o3d_mesh;
  if (!open3d::io::ReadTriangleMesh(path, o3d_mesh)) {
    Fail("cannot read mesh", path, "unsupported or malformed file");
  }
  if (o3d_mesh.triangles_.empty()) {
    Fail("cannot read mesh", path, "mesh has no triangles");
  }
  TriangleMesh mesh;
  mesh.vertices.reserve(o3d_mesh.vertices_.size());
  for (const Eigen::Vector3d& v : o3d_mesh.vertices_) {
    if (!v.allFinite()) Fail("cannot read mesh", path, "non-finite vertex");
    mesh.vertices.push_back(v.cast<float>());
  }
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  mesh.triangles.reserve(o3d_mesh.triangles_.size());
  for (const Eigen::Vector3i& tri : o3d_mesh.triangles_) {
    if ((tri.array() < 0).any() || (tri.array() >= num_vertices).any()) {
      Fail("cannot read mesh", path, "triangle index out of range");
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

}  // namespace graspfill::io
