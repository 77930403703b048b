// SPDX-License-Identifier: BSD-3-Clause
#include "ply_header.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "ply_parser.hpp"

namespace graspfill::io::ply {
namespace {

bool ParseType(const std::string& s, Type* t) {
  static const std::pair<const char*, Type> kNames[] = {
      {"char", Type::kInt8},      {"int8", Type::kInt8},       {"uchar", Type::kUint8},
      {"uint8", Type::kUint8},    {"short", Type::kInt16},     {"int16", Type::kInt16},
      {"ushort", Type::kUint16},  {"uint16", Type::kUint16},   {"int", Type::kInt32},
      {"int32", Type::kInt32},    {"uint", Type::kUint32},     {"uint32", Type::kUint32},
      {"float", Type::kFloat32},  {"float32", Type::kFloat32}, {"double", Type::kFloat64},
      {"float64", Type::kFloat64}};
  for (const auto& [name, type] : kNames) {
    if (s == name) {
      *t = type;
      return true;
    }
  }
  return false;
}

// Reads the next header line (without the newline, without '\r').
bool NextLine(const std::string& bytes, size_t* pos, std::string* line) {
  if (*pos >= bytes.size()) return false;
  const size_t nl = bytes.find('\n', *pos);
  if (nl == std::string::npos) return false;  // a header line always ends in '\n'
  *line = bytes.substr(*pos, nl - *pos);
  if (!line->empty() && line->back() == '\r') line->pop_back();
  *pos = nl + 1;
  return true;
}

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  std::string w;
  while (in >> w) words.push_back(w);
  return words;
}

bool ParseCount(const std::string& s, int64_t* count) {
  if (s.empty() || s.size() > 18) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  *count = std::strtoll(s.c_str(), nullptr, 10);
  return true;
}

// A 'format', 'element' or 'property' line (its words `w`) into the header.
void ReadHeaderLine(const std::vector<std::string>& w, const std::string& where, const std::string& path,
                    const std::string& what, Header* header, bool* have_format) {
  std::vector<Element>& elements = header->elements;
  if (w[0] == "format") {
    if (w.size() != 3 || w[2] != "1.0") Fail(what, path, where + ": expected 'format <type> 1.0'");
    if (w[1] == "ascii")
      header->format = Format::kAscii;
    else if (w[1] == "binary_little_endian")
      header->format = Format::kBinaryLittle;
    else if (w[1] == "binary_big_endian")
      header->format = Format::kBinaryBig;
    else
      Fail(what, path, where + ": unknown format '" + w[1] + "'");
    *have_format = true;
  } else if (w[0] == "element") {
    Element e;
    if (w.size() != 3 || !ParseCount(w[2], &e.count)) {
      Fail(what, path, where + ": expected 'element <name> <count>' with a count >= 0");
    }
    e.name = w[1];
    for (const Element& other : elements) {
      if (other.name == e.name) Fail(what, path, where + ": element '" + e.name + "' declared twice");
    }
    elements.push_back(e);
  } else if (w[0] == "property") {
    if (elements.empty()) Fail(what, path, where + ": property before any element");
    Property p;
    if (w.size() == 3 && ParseType(w[1], &p.type)) {
      p.name = w[2];
    } else if (w.size() == 5 && w[1] == "list" && ParseType(w[2], &p.count_type) && IsInteger(p.count_type) &&
               ParseType(w[3], &p.type)) {
      p.is_list = true;
      p.name = w[4];
    } else {
      Fail(what, path,
           where + ": expected 'property <type> <name>' or 'property list <int type> <type> <name>'");
    }
    for (const Property& other : elements.back().properties) {
      if (other.name == p.name) {
        Fail(what, path, where + ": property '" + p.name + "' declared twice");
      }
    }
    elements.back().properties.push_back(p);
  } else {
    Fail(what, path, where + ": unknown keyword '" + w[0] + "'");
  }
}

}  // namespace

[[noreturn]] void Fail(const std::string& what, const std::string& path, const std::string& why) {
  throw std::runtime_error(what + " '" + path + "': " + why);
}

int TypeBytes(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

bool IsInteger(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

// The header, up to 'end_header', within kMaxHeaderLines and kMaxHeaderBytes.
Header ReadHeader(const std::string& bytes, const std::string& path, const std::string& what) {
  size_t pos = 0;
  std::string line;
  if (!NextLine(bytes, &pos, &line) || line != "ply") {
    Fail(what, path, "not a PLY file (no 'ply' line at the start)");
  }
  Header header;
  bool have_format = false;
  bool ended = false;
  for (int n = 1; n < kMaxHeaderLines; ++n) {
    if (static_cast<int64_t>(pos) > kMaxHeaderBytes) break;
    if (!NextLine(bytes, &pos, &line)) {
      Fail(what, path, "header ends at line " + std::to_string(n + 1) + " without 'end_header'");
    }
    const std::vector<std::string> w = Words(line);
    if (w.empty()) continue;
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      ended = true;
      break;
    }
    ReadHeaderLine(w, "header line " + std::to_string(n + 1), path, what, &header, &have_format);
  }
  if (!ended)
    Fail(what, path,
         "no 'end_header' within the first " + std::to_string(kMaxHeaderLines) + " lines / " +
             std::to_string(kMaxHeaderBytes) + " bytes");
  if (!have_format) Fail(what, path, "no 'format' line in the header");
  header.body_start = pos;
  return header;
}

}  // namespace graspfill::io::ply
