// SPDX-License-Identifier: BSD-3-Clause
// graspfill's own PLY parser (internal to graspfill_io). Open3D's reader
// (rply) segfaulted on a 40-byte header and its ear clipping on a 672-byte
// mesh, read a PLY without `z` with z = 0 and a binary header over an ASCII
// body as floats. This one checks the header and every count against the
// bytes in the file before it allocates, and reads only what graspfill
// needs: the vertex element's scalar properties and the face element's
// index lists. Every error names the file and the element, property or
// line it is about.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace graspfill::io::ply {

/// Largest PLY file read [bytes] (the file is read whole).
constexpr int64_t kMaxFileBytes = int64_t{2} << 30;
/// Header limits: lines and bytes before end_header.
constexpr int kMaxHeaderLines = 1000;
constexpr int64_t kMaxHeaderBytes = 64 * 1024;
/// Most vertices of one face (polygons are fan-triangulated).
constexpr int64_t kMaxFaceVertices = 1024;

struct Parsed {
  int64_t num_vertices{0};
  /// The vertex element's scalar properties by name, one value per vertex
  /// (converted to double; list properties of the vertex are skipped).
  std::map<std::string, std::vector<double>> vertex;
  /// The face element's index lists (`vertex_indices` or `vertex_index`),
  /// flat: face f is indices[face_start[f] .. face_start[f + 1]).
  std::vector<int64_t> face_indices;
  std::vector<int64_t> face_start{0};
  bool has_faces{false};
};

/// Parses `bytes`, the whole file at `path` (named in errors).
/// @throws std::runtime_error "<what> '<path>': <reason>".
Parsed Parse(const std::string& bytes, const std::string& path, const std::string& what, bool want_faces);

/// Reads the file whole (a regular file, at most kMaxFileBytes).
/// @throws std::runtime_error "<what> '<path>': <reason>".
std::string ReadWholeFile(const std::string& path, const std::string& what);

}  // namespace graspfill::io::ply
