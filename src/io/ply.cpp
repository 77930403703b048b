// PLY and mesh files. Writers are hand-written (see ply.hpp for why) and emit
// little-endian bytes explicitly, so output does not depend on the host.
// Readers go through Open3D, which handles every PLY flavour in the wild.
#include "graspfill/io/ply.hpp"

#include "graspfill/io/atomic_file.hpp"

#include <open3d/core/Tensor.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>
#include <open3d/t/geometry/PointCloud.h>
#include <open3d/t/io/PointCloudIO.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace graspfill::io {
namespace {

// Bounds reading a header by hand, so a file that is not PLY is not read
// whole looking for "end_header".
constexpr int kMaxHeaderLines = 256;

[[noreturn]] void Fail(const std::string& what, const std::string& path,
                       const std::string& why) {
  throw std::runtime_error(what + " '" + path + "': " + why);
}

void AppendFloat(std::string* out, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(bits >> (8 * i)));
}

void AppendInt32(std::string* out, int32_t value) {
  const uint32_t bits = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(bits >> (8 * i)));
}

std::string FormatDouble(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

// Atomically: a failed write (full disk) never replaces a good file.
void WriteFile(const std::string& what, const std::string& path,
               const std::string& bytes) {
  WriteFileAtomically(path, bytes, what);
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
      ok = static_cast<bool>(fields >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >>
                             q[2] >> q[3]);
      Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
      ok = ok && std::isfinite(rotation.norm()) &&
           std::abs(rotation.norm() - 1.0) < 1e-3 && std::isfinite(t[0]) &&
           std::isfinite(t[1]) && std::isfinite(t[2]);
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

// Copies an {n, 3} tensor into Vector3f's.
std::vector<Eigen::Vector3f> ToVectors(const open3d::core::Tensor& tensor) {
  const open3d::core::Tensor t =
      tensor.To(open3d::core::Float32).Contiguous();
  const int64_t n = t.GetLength();
  std::vector<Eigen::Vector3f> v(static_cast<size_t>(n));
  const float* p = t.GetDataPtr<float>();
  for (int64_t i = 0; i < n; ++i) {
    v[i] = Eigen::Vector3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  }
  return v;
}

}  // namespace

void WriteCloudPly(const std::string& path, const ObjectCloud& cloud) {
  const size_t n = cloud.points_G.size();
  const bool has_normals = !cloud.normals_G.empty();
  if (has_normals && cloud.normals_G.size() != n) {
    Fail("cannot write PLY", path, "normals are not one per point");
  }
  if (!cloud.provenance.empty() && cloud.provenance.size() != n) {
    Fail("cannot write PLY", path, "provenance is not one per point");
  }
  const bool has_confidence = !cloud.confidence.empty();
  if (has_confidence && cloud.confidence.size() != n) {
    Fail("cannot write PLY", path, "confidence is not one per point");
  }
  // Header comments must stay on one line each.
  std::string frame_name = cloud.frame_name;
  for (char& c : frame_name) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  Eigen::Quaterniond q(cloud.T_C_G.rotation());
  q.normalize();
  const Eigen::Vector3d& t = cloud.T_C_G.translation();

  std::string bytes;
  bytes.reserve(512 + n * (has_normals ? 25 : 13));
  bytes += "ply\nformat binary_little_endian 1.0\n";
  bytes += "comment graspfill object cloud, gripper frame G, meters\n";
  bytes += "comment graspfill frame_name " + frame_name + "\n";
  bytes += "comment graspfill utime " + std::to_string(cloud.utime) + "\n";
  bytes += "comment graspfill seq " + std::to_string(cloud.seq) + "\n";
  bytes += "comment graspfill T_C_G " + FormatDouble(t.x()) + " " +
           FormatDouble(t.y()) + " " + FormatDouble(t.z()) + " " +
           FormatDouble(q.w()) + " " + FormatDouble(q.x()) + " " +
           FormatDouble(q.y()) + " " + FormatDouble(q.z()) + "\n";
  bytes += "comment provenance: 0 observed, 1 surface repair, 2 symmetry\n";
  bytes += "element vertex " + std::to_string(n) + "\n";
  bytes += "property float x\nproperty float y\nproperty float z\n";
  if (has_normals) {
    bytes += "property float nx\nproperty float ny\nproperty float nz\n";
  }
  bytes += "property uchar provenance\n";
  if (has_confidence) bytes += "property float confidence\n";
  bytes += "end_header\n";
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.points_G[i][k]);
    if (has_normals) {
      for (int k = 0; k < 3; ++k) AppendFloat(&bytes, cloud.normals_G[i][k]);
    }
    const Provenance p =
        cloud.provenance.empty() ? Provenance::kObserved : cloud.provenance[i];
    bytes.push_back(static_cast<char>(p));
    if (has_confidence) AppendFloat(&bytes, cloud.confidence[i]);
  }
  WriteFile("cannot write PLY", path, bytes);
}

ObjectCloud ReadCloudPly(const std::string& path) {
  CheckReadable("cannot read PLY", path);
  ObjectCloud cloud;
  ReadHeaderComments(path, &cloud);

  open3d::t::geometry::PointCloud pcd;
  open3d::io::ReadPointCloudOption options;
  options.format = "ply";  // whatever the extension says
  if (!open3d::t::io::ReadPointCloud(path, pcd, options)) {
    Fail("cannot read PLY", path, "not a readable point cloud PLY");
  }
  // HasPointPositions() is false for zero points; a PLY declaring x y z
  // with zero vertices is an empty cloud, not an error.
  if (!pcd.GetPointAttr().Contains("positions")) {
    Fail("cannot read PLY", path, "no x y z vertex properties");
  }
  if (pcd.GetPointPositions().GetLength() == 0) return cloud;
  cloud.points_G = ToVectors(pcd.GetPointPositions());
  const size_t n = cloud.points_G.size();
  if (pcd.HasPointNormals()) cloud.normals_G = ToVectors(pcd.GetPointNormals());

  cloud.provenance.assign(n, Provenance::kObserved);
  if (pcd.HasPointAttr("provenance")) {
    // Other tools may have stored it as float or int; accept exact 0..2.
    const open3d::core::Tensor p =
        pcd.GetPointAttr("provenance").To(open3d::core::Float64).Contiguous();
    if (static_cast<size_t>(p.NumElements()) != n) {
      Fail("cannot read PLY", path, "provenance is not one per point");
    }
    const double* values = p.GetDataPtr<double>();
    for (size_t i = 0; i < n; ++i) {
      const double v = values[i];
      if (v != 0.0 && v != 1.0 && v != 2.0) {
        Fail("cannot read PLY", path,
             "provenance value " + FormatDouble(v) + " at vertex " +
                 std::to_string(i) + " is not 0, 1 or 2");
      }
      cloud.provenance[i] = static_cast<Provenance>(static_cast<int>(v));
    }
  }
  if (pcd.HasPointAttr("confidence")) {
    const open3d::core::Tensor c =
        pcd.GetPointAttr("confidence").To(open3d::core::Float32).Contiguous();
    if (static_cast<size_t>(c.NumElements()) != n) {
      Fail("cannot read PLY", path, "confidence is not one per point");
    }
    const float* values = c.GetDataPtr<float>();
    cloud.confidence.assign(values, values + n);
    for (size_t i = 0; i < n; ++i) {
      if (!(values[i] >= 0.0f && values[i] <= 1.0f)) {
        Fail("cannot read PLY", path,
             "confidence value " + FormatDouble(values[i]) + " at vertex " + std::to_string(i) +
                 " is not in [0, 1]");
      }
    }
  }
  return cloud;
}

void WriteMeshPly(const std::string& path, const TriangleMesh& mesh) {
  const int64_t num_vertices = static_cast<int64_t>(mesh.vertices.size());
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= num_vertices) {
        Fail("cannot write PLY", path,
             "triangle index " + std::to_string(tri[k]) + " out of range");
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
  WriteFile("cannot write PLY", path, bytes);
}

TriangleMesh ReadMesh(const std::string& path) {
  CheckReadable("cannot read mesh", path);
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
