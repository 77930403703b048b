// SPDX-License-Identifier: BSD-3-Clause
// graspfill's PLY parser (clouds and meshes) on arbitrary bytes: an error
// naming the file, or columns of exactly num_vertices values and faces
// whose indices are all in range.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "ply_parser.hpp"

using namespace graspfill::io;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (bool faces : {false, true}) {
    try {
      const ply::Parsed parsed = ply::Parse(bytes, "fuzz.ply", "cannot read PLY", faces);
      FUZZ_CHECK(parsed.vertex.count("x") && parsed.vertex.count("y") && parsed.vertex.count("z"));
      for (const auto& [name, column] : parsed.vertex) {
        FUZZ_CHECK(static_cast<int64_t>(column.size()) == parsed.num_vertices);
      }
      FUZZ_CHECK(parsed.face_start.back() == static_cast<int64_t>(parsed.face_indices.size()));
      for (int64_t i : parsed.face_indices) FUZZ_CHECK(i >= 0 && i < parsed.num_vertices);
    } catch (const std::runtime_error& e) {
      FUZZ_CHECK(std::string(e.what()).find("'fuzz.ply'") != std::string::npos);
    }
  }
  return 0;
}
