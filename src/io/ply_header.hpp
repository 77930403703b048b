// SPDX-License-Identifier: BSD-3-Clause
// The PLY parser's header part (ply_parser.cpp reads the body): the format,
// the elements and their properties, read line by line within
// kMaxHeaderLines and kMaxHeaderBytes. Internal to graspfill_io.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace graspfill::io::ply {

enum class Format { kAscii, kBinaryLittle, kBinaryBig };
enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct Property {
  std::string name;
  Type type{Type::kFloat32};
  bool is_list{false};
  Type count_type{Type::kUint8};
};

struct Element {
  std::string name;
  int64_t count{0};
  std::vector<Property> properties;
};

struct Header {
  Format format{Format::kAscii};
  std::vector<Element> elements;
  size_t body_start{0};  // the byte after 'end_header\n'
};

/// Throws std::runtime_error "<what> '<path>': <why>".
[[noreturn]] void Fail(const std::string& what, const std::string& path, const std::string& why);
/// Bytes of one binary value of type t.
int TypeBytes(Type t);
bool IsInteger(Type t);

/// The header of the PLY file `bytes` (named `path` in errors), up to
/// 'end_header'; every line checked.
Header ReadHeader(const std::string& bytes, const std::string& path, const std::string& what);

}  // namespace graspfill::io::ply
