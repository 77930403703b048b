// SPDX-License-Identifier: BSD-3-Clause
#include "ply_parser.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "graspfill/core/regular_file.hpp"
#include "ply_header.hpp"

namespace graspfill::io::ply {
namespace {

// The body, read value by value with bounds checks; errors say where.
class Body {
 public:
  Body(const std::string& bytes, size_t start, Format format, const std::string& path,
       const std::string& what)
      : bytes_(bytes), pos_(start), format_(format), path_(path), what_(what) {}

  size_t remaining() const { return bytes_.size() - pos_; }

  // One value of type t; `where` names it for errors (only built on failure).
  template <typename Where>
  double Read(Type t, const Where& where) {
    return format_ == Format::kAscii ? ReadAscii(t, where) : ReadBinary(t, where);
  }

  // After the last element: nothing but (ASCII) whitespace may follow.
  void ExpectEnd() {
    if (format_ == Format::kAscii) {
      while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
      if (pos_ < bytes_.size()) {
        Fail(what_, path_,
             "unexpected data after the last element (at byte " + std::to_string(pos_) +
                 "): more values than the header declares");
      }
    } else if (pos_ < bytes_.size()) {
      Fail(what_, path_,
           std::to_string(bytes_.size() - pos_) +
               " bytes after the last element: the body does not match the binary header "
               "(an ASCII body, or counts that are too small?)");
    }
  }

 private:
  template <typename Where>
  double ReadBinary(Type t, const Where& where) {
    const int n = TypeBytes(t);
    if (remaining() < static_cast<size_t>(n)) {
      Fail(what_, path_, "file ends inside " + where() + " (the body is shorter than the header declares)");
    }
    uint8_t b[8];
    std::memcpy(b, bytes_.data() + pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    if (format_ == Format::kBinaryBig) {
      for (int i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    }
    switch (t) {
      case Type::kInt8:
        return static_cast<int8_t>(b[0]);
      case Type::kUint8:
        return b[0];
      case Type::kInt16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kUint16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kInt32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kUint32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kFloat32: {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kFloat64: {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    }
    return 0.0;
  }

  template <typename Where>
  double ReadAscii(Type t, const Where& where) {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    const size_t begin = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    if (begin == pos_) {
      Fail(what_, path_, "file ends before " + where() + " (fewer values than the header declares)");
    }
    // Copy the token (bounded: a number is short) so strtod stops at its end.
    if (pos_ - begin > 64) Fail(what_, path_, where() + ": value too long to be a number");
    char token[65];
    std::memcpy(token, bytes_.data() + begin, pos_ - begin);
    token[pos_ - begin] = '\0';
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(token, &end);
    if (end == token || *end != '\0') {
      Fail(what_, path_, where() + ": '" + std::string(token) + "' is not a number");
    }
    if (IsInteger(t) && (v != std::floor(v) || !std::isfinite(v))) {
      Fail(what_, path_, where() + ": '" + std::string(token) + "' is not an integer");
    }
    return v;
  }

  const std::string& bytes_;
  size_t pos_;
  Format format_;
  const std::string& path_;
  const std::string& what_;
};

// The 'vertex' element, which must have scalar x, y and z.
const Element& VertexElement(const Header& header, const std::string& path, const std::string& what) {
  const Element* vertex_element = nullptr;
  for (const Element& e : header.elements) {
    if (e.name == "vertex") vertex_element = &e;
  }
  if (vertex_element == nullptr) Fail(what, path, "no 'vertex' element");
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const Property& p : vertex_element->properties) {
      if (p.name == axis) {
        if (p.is_list) Fail(what, path, std::string("vertex property '") + axis + "' is a list");
        found = true;
      }
    }
    if (!found) Fail(what, path, std::string("no '") + axis + "' vertex property");
  }
  return *vertex_element;
}

// Counts against the body before anything is allocated: every value takes
// at least 1 byte (binary) or 2 (ASCII: a digit and a separator), every
// list at least its count.
void CheckDeclaredCounts(const std::string& bytes, const Header& header, const std::string& path,
                         const std::string& what) {
  const size_t body_bytes = bytes.size() - header.body_start;
  const bool ascii = header.format == Format::kAscii;
  int64_t min_total = 0;
  for (const Element& e : header.elements) {
    int64_t per = 0;
    for (const Property& p : e.properties) {
      per += p.is_list ? (ascii ? 2 : TypeBytes(p.count_type)) : (ascii ? 2 : TypeBytes(p.type));
    }
    per = std::max<int64_t>(per, 0);
    if (per > 0 && e.count > static_cast<int64_t>(body_bytes) / per + 1) {
      Fail(what, path,
           "element '" + e.name + "' declares " + std::to_string(e.count) + " entries, more than the " +
               std::to_string(body_bytes) + " bytes of the body can hold");
    }
    min_total += per * e.count;
  }
  if (!ascii && min_total > static_cast<int64_t>(body_bytes)) {
    Fail(what, path,
         "the body has " + std::to_string(body_bytes) + " bytes, the header declares at least " +
             std::to_string(min_total));
  }
}

// A binary header over a text body of the right size (the case:
// "0.1 0.2 0.3\n" is 12 bytes, one float vertex) would be read as floats.
// Binary data that is all number characters with line breaks is
// practically impossible; text is.
void CheckBinaryBodyIsNotText(const std::string& bytes, const Header& header, const std::string& path,
                              const std::string& what) {
  if (header.format == Format::kAscii || bytes.size() == header.body_start) return;
  bool text = false;
  bool only_number_chars = true;
  for (size_t i = header.body_start; i < bytes.size() && only_number_chars; ++i) {
    const char c = bytes[i];
    if (c == '\n') text = true;
    only_number_chars = (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E' ||
                        c == ' ' || c == '\t' || c == '\r' || c == '\n';
  }
  if (text && only_number_chars) {
    Fail(what, path,
         "the body is ASCII text but the header says binary: the body does not match "
         "the binary header");
  }
}

// The position of the face element's index list ('vertex_indices' or
// 'vertex_index', integers).
int FaceListOf(const Element& e, const std::string& path, const std::string& what) {
  int face_list = -1;
  for (size_t k = 0; k < e.properties.size(); ++k) {
    const Property& p = e.properties[k];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      face_list = static_cast<int>(k);
    }
  }
  if (face_list < 0) Fail(what, path, "face element without a 'vertex_indices' list");
  if (!IsInteger(e.properties[static_cast<size_t>(face_list)].type)) {
    Fail(what, path, "face property 'vertex_indices' is not an integer list");
  }
  return face_list;
}

// One list property's values; kept (into out's faces) when `keep`: the
// face's index list, each index checked against the vertex count.
template <typename Where>
void ReadList(Body* body, const Property& p, bool keep, const Where& where, const std::string& path,
              const std::string& what, Parsed* out) {
  const double count = body->Read(p.count_type, where);
  if (count < 0 || count > static_cast<double>(body->remaining())) {
    Fail(what, path,
         where() + ": list of " + std::to_string(static_cast<int64_t>(count)) +
             " values, more than the file holds");
  }
  if (keep && (count < 3 || count > kMaxFaceVertices)) {
    Fail(what, path,
         where() + ": a face of " + std::to_string(static_cast<int64_t>(count)) + " vertices (expected 3.." +
             std::to_string(kMaxFaceVertices) + ")");
  }
  for (int64_t j = 0; j < static_cast<int64_t>(count); ++j) {
    const double v = body->Read(p.type, where);
    if (keep) {
      if (!(v >= 0 && v < static_cast<double>(out->num_vertices))) {
        Fail(what, path,
             where() + ": vertex index " + std::to_string(static_cast<int64_t>(v)) + " out of range (" +
                 std::to_string(out->num_vertices) + " vertices)");
      }
      out->face_indices.push_back(static_cast<int64_t>(v));
    }
  }
  if (keep) out->face_start.push_back(static_cast<int64_t>(out->face_indices.size()));
}

// One element's entries: the vertex's scalars into `columns` (null: not
// the vertex; an entry null: a list), the face's index lists into out's
// faces (face_list >= 0).
void ReadElement(Body* body, const Element& e, const std::vector<std::vector<double>*>* columns,
                 int face_list, const std::string& path, const std::string& what, Parsed* out) {
  for (int64_t i = 0; i < e.count; ++i) {
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      auto where = [&] { return e.name + " " + std::to_string(i) + ", property '" + p.name + "'"; };
      if (p.is_list) {
        ReadList(body, p, static_cast<int>(k) == face_list, where, path, what, out);
      } else {
        const double v = body->Read(p.type, where);
        if (columns) (*(*columns)[k])[static_cast<size_t>(i)] = v;
      }
    }
  }
}

}  // namespace

std::string ReadWholeFile(const std::string& path, const std::string& what) {
  return ReadRegularFile(path, kMaxFileBytes, what);
}

Parsed Parse(const std::string& bytes, const std::string& path, const std::string& what, bool want_faces) {
  const Header header = ReadHeader(bytes, path, what);
  const Element& vertex_element = VertexElement(header, path, what);
  CheckDeclaredCounts(bytes, header, path, what);
  CheckBinaryBodyIsNotText(bytes, header, path, what);

  Parsed out;
  out.num_vertices = vertex_element.count;
  const size_t nv = static_cast<size_t>(vertex_element.count);
  std::vector<std::vector<double>*> columns(vertex_element.properties.size(), nullptr);
  for (size_t k = 0; k < vertex_element.properties.size(); ++k) {
    const Property& p = vertex_element.properties[k];
    if (!p.is_list) {
      auto& column = out.vertex[p.name];
      column.resize(nv);
      columns[k] = &column;
    }
  }

  Body body(bytes, header.body_start, header.format, path, what);
  for (const Element& e : header.elements) {
    if (e.properties.empty()) continue;  // nothing to read, whatever its count
    int face_list = -1;
    if (want_faces && e.name == "face") {
      face_list = FaceListOf(e, path, what);
      out.has_faces = true;
      out.face_start.reserve(static_cast<size_t>(e.count) + 1);
    }
    const bool is_vertex = &e == &vertex_element;
    ReadElement(&body, e, is_vertex ? &columns : nullptr, face_list, path, what, &out);
  }
  body.ExpectEnd();
  return out;
}

}  // namespace graspfill::io::ply
