// SPDX-License-Identifier: BSD-3-Clause
// Mesh files by extension: PLY through WriteMeshPly, STL and OBJ here (both
// simple enough to write exactly, with no header that varies run to run).
#include "graspfill/io/mesh_export.hpp"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "graspfill/io/atomic_file.hpp"
#include "graspfill/io/ply.hpp"

namespace graspfill::io {
namespace {

void CheckIndices(const std::string& path, const TriangleMesh& mesh) {
  const int64_t num_vertices = static_cast<int64_t>(mesh.vertices.size());
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= num_vertices) {
        throw std::runtime_error("cannot write mesh '" + path + "': triangle index " +
                                 std::to_string(tri[k]) + " out of range");
      }
    }
  }
}

// Little-endian bytes of a 32-bit value (as the STL format wants).
template <typename T>
void AppendLe(std::string* bytes, T value) {
  static_assert(sizeof(T) == 4);
  uint32_t u;
  std::memcpy(&u, &value, 4);
  for (int i = 0; i < 4; ++i) bytes->push_back(static_cast<char>((u >> (8 * i)) & 0xff));
}

std::string StlBytes(const TriangleMesh& mesh) {
  std::string bytes(80, '\0');
  const char header[] = "binary STL written by graspfill";
  std::memcpy(bytes.data(), header, sizeof(header) - 1);
  bytes.reserve(84 + mesh.triangles.size() * 50);
  AppendLe(&bytes, static_cast<uint32_t>(mesh.triangles.size()));
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[tri[0]];
    const Eigen::Vector3f n = (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a);
    const float length = n.norm();
    const Eigen::Vector3f unit = length > 0.0f ? Eigen::Vector3f(n / length) : Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) AppendLe(&bytes, unit[k]);
    for (int v = 0; v < 3; ++v) {
      for (int k = 0; k < 3; ++k) AppendLe(&bytes, mesh.vertices[tri[v]][k]);
    }
    bytes.append(2, '\0');  // attribute byte count
  }
  return bytes;
}

std::string ObjBytes(const TriangleMesh& mesh) {
  std::string text = "# graspfill mesh\n";
  char line[96];
  for (const Eigen::Vector3f& v : mesh.vertices) {
    std::snprintf(line, sizeof(line), "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    text += line;
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    std::snprintf(line, sizeof(line), "f %d %d %d\n", t.x() + 1, t.y() + 1, t.z() + 1);
    text += line;
  }
  return text;
}

}  // namespace

std::optional<MeshFormat> MeshFormatOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".ply") return MeshFormat::kPly;
  if (ext == ".stl") return MeshFormat::kStl;
  if (ext == ".obj") return MeshFormat::kObj;
  return std::nullopt;
}

void WriteMesh(const std::string& path, const TriangleMesh& mesh, IfExists if_exists) {
  const std::optional<MeshFormat> format = MeshFormatOf(path);
  if (!format) {
    throw std::runtime_error("cannot write mesh '" + path + "': unknown extension (use .ply, .stl or .obj)");
  }
  if (*format == MeshFormat::kPly) {
    WriteMeshPly(path, mesh, if_exists);
    return;
  }
  CheckIndices(path, mesh);
  WriteFileAtomically(path, *format == MeshFormat::kStl ? StlBytes(mesh) : ObjBytes(mesh),
                      "cannot write mesh", if_exists);
}

}  // namespace graspfill::io
