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
  value.erase(std::remove_if(value.begin(), value.end(),
                             [](unsigned char c) { return std::isspace(c); }),
              value.end());
  if (value == "X_UP") return UpAxis::kX;
  if (value == "Z_UP") return UpAxis::kZ;
  return UpAxis::kY;
}

// Rotation taking the file's up axis to +z.
Eigen::Matrix3f UpToZ(UpAxis up) {
  switch (up) {
    case UpAxis::kZ: return Eigen::Matrix3f::Identity();
    case UpAxis::kY:
      return Eigen::AngleAxisf(kHalfPi, Eigen::Vector3f::UnitX())
          .toRotationMatrix();
    case UpAxis::kX:
      return Eigen::AngleAxisf(-kHalfPi, Eigen::Vector3f::UnitY())
          .toRotationMatrix();
  }
  return Eigen::Matrix3f::Identity();
}

}  // namespace

TriangleMesh ReadMeshFile(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw std::runtime_error("mesh file not found: " + path);
  }
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // ValidateDataStructure runs first and rejects out-of-range indices
  // (assimp's own later steps would read past the vertices). No
  // JoinIdenticalVertices: it compares normals too, and crashed on such
  // files; vertices are merged by position below.
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    throw std::runtime_error("cannot read mesh file: " + path + ": " + importer.GetErrorString());
  }
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
      mesh.triangles.emplace_back(remap[face.mIndices[0]], remap[face.mIndices[1]],
                                  remap[face.mIndices[2]]);
    }
  }
  if (mesh.triangles.empty()) throw std::runtime_error("mesh has no triangles: " + path);
  return mesh;
}

}  // namespace graspfill::claw
