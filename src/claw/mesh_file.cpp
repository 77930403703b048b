// SPDX-License-Identifier: BSD-3-Clause
#include "graspfill/claw/mesh_file.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "graspfill/claw/claw_limits.hpp"
#include "graspfill/core/regular_file.hpp"

namespace graspfill::claw {
namespace {

namespace fs = std::filesystem;

constexpr float kHalfPi = 1.57079632679489662f;

enum class UpAxis { kX, kY, kZ };

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// COLLADA's <up_axis> (in <asset>, at the head of the file; Y_UP when
// absent, as the COLLADA spec says). Assimp would turn every file to Y-up;
// it is told to keep the file's axes and the turn to +z-up is done here.
UpAxis ColladaUpAxis(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  const size_t open = head.find("<up_axis>");
  if (open == std::string::npos) return UpAxis::kY;
  const size_t begin = open + std::strlen("<up_axis>");
  const size_t end = head.find("</up_axis>", begin);
  std::string value = head.substr(begin, end == std::string::npos ? 0 : end - begin);
  value.erase(std::remove_if(value.begin(), value.end(), [](unsigned char c) { return std::isspace(c); }),
              value.end());
  if (value == "X_UP") return UpAxis::kX;
  if (value == "Z_UP") return UpAxis::kZ;
  return UpAxis::kY;
}

// Rotation taking the file's up axis to +z.
Eigen::Matrix3f UpToZ(UpAxis up) {
  switch (up) {
    case UpAxis::kZ:
      return Eigen::Matrix3f::Identity();
    case UpAxis::kY:
      return Eigen::AngleAxisf(kHalfPi, Eigen::Vector3f::UnitX()).toRotationMatrix();
    case UpAxis::kX:
      return Eigen::AngleAxisf(-kHalfPi, Eigen::Vector3f::UnitY()).toRotationMatrix();
  }
  return Eigen::Matrix3f::Identity();
}

std::runtime_error TooManyTriangles(const std::string& path, int64_t triangles) {
  return std::runtime_error("mesh file " + path + ": " + std::to_string(triangles) +
                            " triangles, over the claw's limit of " + std::to_string(kMaxClawTriangles) +
                            " (claw_limits.hpp; simplify the mesh)");
}

// A binary STL's triangle count (its header's, when the file's size agrees:
// 84 bytes and 50 per triangle), or -1 for any other file.
int64_t BinaryStlTriangles(const std::string& path, int64_t bytes) {
  if (bytes < 84) return -1;
  std::ifstream in(path, std::ios::binary);
  unsigned char header[84];
  if (!in.read(reinterpret_cast<char*>(header), sizeof(header))) return -1;
  const int64_t count =
      int64_t{header[80]} | int64_t{header[81]} << 8 | int64_t{header[82]} << 16 | int64_t{header[83]} << 24;
  return bytes == 84 + 50 * count ? count : -1;
}

// Before assimp opens it: a regular file (assimp would block on a FIFO),
// small enough to hold no more triangles than the claw has left (a binary
// STL, the usual claw mesh, is counted from its header).
void CheckMeshFile(const std::string& path, int64_t max_triangles) {
  const std::string why = NotARegularFile(path);
  if (why == "no such file") throw std::runtime_error("mesh file not found: " + path);
  if (!why.empty()) throw std::runtime_error("cannot read mesh file: " + path + ": " + why);
  std::error_code ec;
  const auto bytes = static_cast<int64_t>(fs::file_size(path, ec));
  if (!ec && bytes > kMaxMeshFileBytes) {
    throw std::runtime_error("mesh file " + path + ": " + std::to_string(bytes) +
                             " bytes, over the limit of " + std::to_string(kMaxMeshFileBytes) +
                             " for a claw mesh (claw_limits.hpp; simplify the mesh)");
  }
  if (const int64_t stl = ec ? -1 : BinaryStlTriangles(path, bytes); stl > max_triangles) {
    throw TooManyTriangles(path, stl);
  }
}

// Before the vertices are merged (the costly part): the file's faces
// against what is left of the claw's triangle budget.
void CheckTriangleCount(const aiScene& scene, const std::string& path, int64_t max_triangles) {
  int64_t faces = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) faces += scene.mMeshes[m]->mNumFaces;
  if (faces > max_triangles) throw TooManyTriangles(path, faces);
}

}  // namespace

TriangleMesh ReadMeshFile(const std::string& path, int64_t max_triangles) {
  CheckMeshFile(path, max_triangles);
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // ValidateDataStructure runs first and rejects out-of-range indices
  // (assimp's own later steps would read past the vertices). No
  // JoinIdenticalVertices: it compares normals too, and crashed on such
  // files; vertices are merged by position below.
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    throw std::runtime_error("cannot read mesh file: " + path + ": " + importer.GetErrorString());
  }
  CheckTriangleCount(*scene, path, max_triangles);
  const bool collada = Lower(fs::path(path).extension().string()) == ".dae";
  const Eigen::Matrix3f R = collada ? UpToZ(ColladaUpAxis(path)) : Eigen::Matrix3f::Identity();

  TriangleMesh mesh;
  // Exact positions (bit patterns, so -0 and NaNs are kept apart) to index.
  std::map<std::array<uint32_t, 3>, int> index_of;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* in = scene->mMeshes[m];
    std::vector<int> remap(in->mNumVertices);
    for (unsigned i = 0; i < in->mNumVertices; ++i) {
      const Eigen::Vector3f v =
          R * Eigen::Vector3f(in->mVertices[i].x, in->mVertices[i].y, in->mVertices[i].z);
      std::array<uint32_t, 3> key;
      std::memcpy(key.data(), v.data(), sizeof(key));
      const auto [it, added] = index_of.emplace(key, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(v);
      remap[i] = it->second;
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      mesh.triangles.emplace_back(remap[face.mIndices[0]], remap[face.mIndices[1]], remap[face.mIndices[2]]);
    }
  }
  if (mesh.triangles.empty()) throw std::runtime_error("mesh has no triangles: " + path);
  return mesh;
}

}  // namespace graspfill::claw
