// SPDX-License-Identifier: MIT
#pragma once

// PLY loader: ascii, binary_little_endian and binary_big_endian.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/mesh/io_common.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

/// The vertices, triangles and other per-vertex scalar properties of a PLY
/// file (e.g. `label`, `red` of a labeled cloud written by
/// write_labeled_cloud_ply).
struct PlyContent {
  Eigen::Matrix3Xd vertices;   ///< x, y, z of the `vertex` element
  Eigen::Matrix3Xi triangles;  ///< the `face` element, fan-triangulated (may be empty)
  /// Other scalar properties of `vertex`, by name, one value per vertex.
  std::map<std::string, std::vector<double>> vertex_properties;
};

namespace detail {

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

inline bool ply_type_from_name(std::string_view n, PlyType& t) {
  struct Entry {
    const char* name;
    PlyType type;
  };
  static const Entry table[] = {
      {"char", PlyType::int8},      {"int8", PlyType::int8},       {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},    {"short", PlyType::int16},     {"int16", PlyType::int16},
      {"ushort", PlyType::uint16},  {"uint16", PlyType::uint16},   {"int", PlyType::int32},
      {"int32", PlyType::int32},    {"uint", PlyType::uint32},     {"uint32", PlyType::uint32},
      {"float", PlyType::float32},  {"float32", PlyType::float32}, {"double", PlyType::float64},
      {"float64", PlyType::float64}};
  for (const auto& e : table)
    if (n == e.name) {
      t = e.type;
      return true;
    }
  return false;
}

/// What a PLY scalar type is: its size in bytes and, for the integer
/// types, the range of its values.
struct PlyTypeInfo {
  std::size_t size = 0;
  bool integral = false;
  std::int64_t lo = 0, hi = 0;  // integer types only
};

inline PlyTypeInfo ply_type_info(PlyType t) {
  switch (t) {
    case PlyType::int8: return {1, true, -128, 127};
    case PlyType::uint8: return {1, true, 0, 255};
    case PlyType::int16: return {2, true, -32768, 32767};
    case PlyType::uint16: return {2, true, 0, 65535};
    case PlyType::int32: return {4, true, -2147483648LL, 2147483647LL};
    case PlyType::uint32: return {4, true, 0, 4294967295LL};
    case PlyType::float32: return {4, false, 0, 0};
    case PlyType::float64: return {8, false, 0, 0};
  }
  return {};
}

inline std::size_t ply_type_size(PlyType t) { return ply_type_info(t).size; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  // item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;
};

enum class PlyFormat { ascii, binary_le, binary_be };

/// Reads values of the body one at a time, in ascii or binary, and says
/// where it is for error messages.
class PlyValueReader {
 public:
  PlyValueReader(std::string_view data, std::size_t start, std::size_t start_line, PlyFormat format,
                 const std::string& name)
      : data_(data), pos_(start), line_(start_line), format_(format), name_(name) {}

  /// Reads one value of type `t`; `what` describes it for errors.
  double read(PlyType t, const std::string& what) {
    if (format_ == PlyFormat::ascii) return read_ascii(t, what);
    const std::size_t n = ply_type_size(t);
    if (data_.size() - pos_ < n) fail("file ends inside " + what);
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    if (format_ == PlyFormat::binary_be)
      for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    const std::size_t at = pos_;
    pos_ += n;
    double v = 0;
    switch (t) {
      case PlyType::int8: v = static_cast<std::int8_t>(b[0]); break;
      case PlyType::uint8: v = b[0]; break;
      case PlyType::int16: { std::int16_t x; std::memcpy(&x, b, 2); v = x; break; }
      case PlyType::uint16: { std::uint16_t x; std::memcpy(&x, b, 2); v = x; break; }
      case PlyType::int32: { std::int32_t x; std::memcpy(&x, b, 4); v = x; break; }
      case PlyType::uint32: { std::uint32_t x; std::memcpy(&x, b, 4); v = x; break; }
      case PlyType::float32: { float x; std::memcpy(&x, b, 4); v = static_cast<double>(x); break; }
      case PlyType::float64: std::memcpy(&v, b, 8); break;
    }
    if (!std::isfinite(v)) fail_at(at, what + " is not finite");
    return v;
  }

  /// Skips `n` binary values of type `t` (binary formats only).
  void skip(PlyType t, std::uint64_t n, const std::string& what) {
    const std::uint64_t bytes = n * ply_type_size(t);
    if (data_.size() - pos_ < bytes) fail("file ends inside " + what);
    pos_ += static_cast<std::size_t>(bytes);
  }

  /// In ascii, each element item must end its line.
  void end_item(const std::string& what) {
    if (format_ != PlyFormat::ascii) return;
    while (pos_ < data_.size() && is_space(data_[pos_])) ++pos_;
    if (pos_ < data_.size() && data_[pos_] != '\n') fail("extra values after " + what);
    if (pos_ < data_.size()) {
      ++pos_;
      ++line_;
    }
  }

  /// Trailing content after the last element: blank text is fine in ascii.
  bool at_end_or_blank() const {
    for (std::size_t i = pos_; i < data_.size(); ++i)
      if (!(is_space(data_[i]) || data_[i] == '\n')) return false;
    return true;
  }

  bool at_end() const noexcept { return pos_ == data_.size(); }

  bool ascii() const noexcept { return format_ == PlyFormat::ascii; }

  [[noreturn]] void fail(const std::string& reason) const { fail_at(pos_, reason); }
  [[noreturn]] void fail_at(std::size_t at, const std::string& reason) const {
    if (format_ == PlyFormat::ascii) throw ParseError(name_, line_, reason);
    throw ParseError(name_, 0, "byte offset " + std::to_string(at) + ": " + reason);
  }

 private:
  double read_ascii(PlyType t, const std::string& what) {
    while (pos_ < data_.size() && is_space(data_[pos_])) ++pos_;
    if (pos_ >= data_.size()) fail("file ends inside " + what);
    if (data_[pos_] == '\n') fail("line ends inside " + what);
    std::size_t end = pos_;
    while (end < data_.size() && !is_space(data_[end]) && data_[end] != '\n') ++end;
    const std::string_view tok = data_.substr(pos_, end - pos_);
    double v = 0;
    const PlyTypeInfo type = ply_type_info(t);
    if (type.integral) {
      std::int64_t i = 0;
      if (!token_to_int64(tok, i)) fail(what + ": " + show_token(tok) + " is not an integer");
      // Within the declared type, as a binary file's bytes always are (a
      // uchar of 300 or -5 was taken as it was written).
      if (i < type.lo || i > type.hi)
        fail(what + ": " + show_token(tok) + " is out of the range of its type [" + std::to_string(type.lo) + ", " +
             std::to_string(type.hi) + "]");
      v = static_cast<double>(i);
    } else if (!token_to_double(tok, v)) {
      fail(what + ": " + show_token(tok) + " is not a finite number");
    }
    pos_ = end;
    return v;
  }

  std::string_view data_;
  std::size_t pos_;
  std::size_t line_;
  PlyFormat format_;
  const std::string& name_;
};

inline PlyContent parse_ply(std::string_view data, const std::string& name, bool keep_vertex_properties) {
  LineCursor header(data);
  std::string_view line;
  if (!header.next(line) || line != "ply") throw ParseError(name, 1, "not a PLY file (first line is not 'ply')");
  PlyFormat format = PlyFormat::ascii;
  bool have_format = false, have_end = false;
  std::vector<PlyElement> elements;
  while (header.next(line)) {
    const std::size_t ln = header.line_number();
    std::string_view rest = line;
    const std::string_view key = next_token(rest);
    if (key == "comment" || key == "obj_info" || key.empty()) continue;
    if (key == "format") {
      const std::string_view f = next_token(rest);
      if (f == "ascii") format = PlyFormat::ascii;
      else if (f == "binary_little_endian") format = PlyFormat::binary_le;
      else if (f == "binary_big_endian") format = PlyFormat::binary_be;
      else throw ParseError(name, ln, "unknown PLY format " + show_token(f));
      if (next_token(rest) != "1.0") throw ParseError(name, ln, "unsupported PLY version (expected 1.0)");
      expect_line_end(rest, name, ln, "'format " + std::string(f) + " 1.0'");
      if (have_format) throw ParseError(name, ln, "a second 'format' line");
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      e.name = std::string(next_token(rest));
      std::int64_t count = -1;
      if (e.name.empty() || !token_to_int64(next_token(rest), count) || count < 0)
        throw ParseError(name, ln, "expected 'element NAME COUNT'");
      expect_line_end(rest, name, ln, "'element NAME COUNT'");
      for (const auto& other : elements)
        if (other.name == e.name)
          throw ParseError(name, ln, "a second element " + show_token(e.name) + " (the first at line " +
                                         std::to_string(other.line) + "): which one holds the data is ambiguous");
      e.count = static_cast<std::uint64_t>(count);
      e.line = ln;
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) throw ParseError(name, ln, "'property' before any 'element'");
      PlyProperty p;
      std::string_view type = next_token(rest);
      if (type == "list") {
        p.is_list = true;
        const std::string_view ct = next_token(rest);
        if (!ply_type_from_name(ct, p.count_type)) throw ParseError(name, ln, "unknown PLY type " + show_token(ct));
        if (p.count_type == PlyType::float32 || p.count_type == PlyType::float64)
          throw ParseError(name, ln, "list count type must be an integer type");
        type = next_token(rest);
      }
      if (!ply_type_from_name(type, p.type)) throw ParseError(name, ln, "unknown PLY type " + show_token(type));
      p.name = std::string(next_token(rest));
      if (p.name.empty()) throw ParseError(name, ln, "property has no name");
      expect_line_end(rest, name, ln, "the property name " + show_token(p.name));
      for (const auto& other : elements.back().properties)
        if (other.name == p.name)
          throw ParseError(name, ln, "element " + show_token(elements.back().name) + " has a second property " +
                                         show_token(p.name));
      elements.back().properties.push_back(p);
    } else if (key == "end_header") {
      expect_line_end(rest, name, ln, "'end_header'");
      have_end = true;
      break;
    } else {
      throw ParseError(name, ln, "unknown PLY header keyword " + show_token(key));
    }
  }
  if (!have_end) throw ParseError(name, header.line_number(), "PLY header has no 'end_header'");
  if (!have_format) throw ParseError(name, 2, "PLY header has no 'format' line");

  // Roles of the vertex and face properties.
  const PlyElement* vertex = nullptr;
  for (const auto& e : elements)
    if (e.name == "vertex") vertex = &e;
  if (!vertex) throw ParseError(name, header.line_number(), "PLY file has no 'vertex' element");
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t i = 0; i < vertex->properties.size(); ++i) {
    const auto& p = vertex->properties[i];
    if (p.is_list) continue;
    if (p.name == "x") ix = static_cast<int>(i);
    if (p.name == "y") iy = static_cast<int>(i);
    if (p.name == "z") iz = static_cast<int>(i);
  }
  if (ix < 0 || iy < 0 || iz < 0)
    throw ParseError(name, vertex->line, "element 'vertex' lacks a scalar property x, y or z");
  if (vertex->count > static_cast<std::uint64_t>(INT32_MAX))
    throw ParseError(name, vertex->line, "too many vertices");
  // Every element's items need bytes: refuse counts the rest of the file
  // cannot hold before allocating or looping over them. Binary items take
  // at least their scalar sizes plus their list counts' sizes (an element
  // without properties takes none and is skipped); ascii items at least a
  // value per property (a list's count), each with a blank or the line
  // break after it, or an empty line (the last line break may be missing).
  {
    const std::uint64_t body = data.size() - header.position();
    const bool text = format == PlyFormat::ascii;
    std::uint64_t need = 0;
    for (const auto& e : elements) {
      std::uint64_t item = 0;
      if (text) {
        item = e.properties.empty() ? 1 : 2 * std::uint64_t{e.properties.size()};
      } else {
        for (const auto& p : e.properties) item += ply_type_size(p.is_list ? p.count_type : p.type);
        if (item == 0) continue;
      }
      const std::uint64_t room = body + (text ? 1 : 0) - std::min(need, body + (text ? 1 : 0));
      if (e.count > room / item)
        throw ParseError(name, e.line,
                         "element " + show_token(e.name) + " declares " + std::to_string(e.count) +
                             " items, more than the " + std::to_string(body) +
                             " bytes after the header can hold");
      need += e.count * item;
    }
  }
  const std::int64_t nv = static_cast<std::int64_t>(vertex->count);

  PlyContent out;
  out.vertices.resize(3, static_cast<Index>(nv));
  std::vector<int> tri;
  std::vector<int> poly;
  std::vector<std::vector<double>*> extra(vertex->properties.size(), nullptr);
  if (keep_vertex_properties)
    for (std::size_t i = 0; i < vertex->properties.size(); ++i) {
      const auto& p = vertex->properties[i];
      if (!p.is_list && p.name != "x" && p.name != "y" && p.name != "z") {
        auto& vec = out.vertex_properties[p.name];
        vec.resize(static_cast<std::size_t>(nv));
        extra[i] = &vec;
      }
    }

  PlyValueReader reader(data, header.position(), header.line_number() + 1, format, name);
  for (const auto& e : elements) {
    const bool is_vertex = &e == vertex;
    int face_list = -1;
    if (e.name == "face") {
      for (std::size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].is_list && (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
          face_list = static_cast<int>(i);
      if (face_list < 0)
        for (std::size_t i = 0; i < e.properties.size() && face_list < 0; ++i)
          if (e.properties[i].is_list) face_list = static_cast<int>(i);
      if (face_list < 0) throw ParseError(name, e.line, "element 'face' has no list property of vertex indices");
    }
    if (e.properties.empty() && !reader.ascii()) continue;  // no bytes to read
    for (std::uint64_t item = 0; item < e.count; ++item) {
      const std::string where = "element " + show_token(e.name) + " item " + std::to_string(item);
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        const std::string what = where + " property " + show_token(p.name);
        if (!p.is_list) {
          if (!is_vertex && !reader.ascii()) {
            reader.skip(p.type, 1, what);
            continue;
          }
          const double v = reader.read(p.type, what);
          if (is_vertex) {
            const Index col = static_cast<Index>(item);
            if (static_cast<int>(i) == ix) out.vertices(0, col) = v;
            else if (static_cast<int>(i) == iy) out.vertices(1, col) = v;
            else if (static_cast<int>(i) == iz) out.vertices(2, col) = v;
            else if (extra[i]) (*extra[i])[static_cast<std::size_t>(item)] = v;
          }
          continue;
        }
        const double count = reader.read(p.count_type, what + " count");
        if (count < 0) reader.fail(what + ": negative list count");
        const auto n = static_cast<std::uint64_t>(count);
        if (static_cast<int>(i) != face_list) {
          if (reader.ascii())
            for (std::uint64_t k = 0; k < n; ++k) reader.read(p.type, what);
          else
            reader.skip(p.type, n, what);
          continue;
        }
        if (n < 3) reader.fail(where + ": face has " + std::to_string(n) + " vertices, needs at least 3");
        poly.clear();
        for (std::uint64_t k = 0; k < n; ++k) {
          const double idx = reader.read(p.type, what);
          if (idx != std::floor(idx))
            reader.fail(where + ": vertex index " + format_value(idx) + " is not an integer");
          if (idx < 0 || idx >= static_cast<double>(nv))  // |idx| < 2^53 below: exact in long long
            reader.fail(where + ": vertex index " +
                        (std::abs(idx) < 9007199254740992.0 ? std::to_string(static_cast<long long>(idx))
                                                             : format_value(idx)) +
                        " is out of range (" + std::to_string(nv) + " vertices)");
          poly.push_back(static_cast<int>(idx));
        }
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
          tri.push_back(poly[0]);
          tri.push_back(poly[k]);
          tri.push_back(poly[k + 1]);
        }
      }
      reader.end_item(where);
    }
  }
  // (Binary: any byte left is data the header does not declare, as in
  // binary STL; an undercounted element would otherwise be cut silently.)
  if (reader.ascii() ? !reader.at_end_or_blank() : !reader.at_end())
    reader.fail("extra data after the last element");
  out.triangles = Eigen::Map<const Eigen::Matrix3Xi>(tri.data(), 3, static_cast<Index>(tri.size() / 3));
  return out;
}

}  // namespace detail

/// Reads a PLY file from `in` (`name` for errors): ascii, binary_little_endian
/// or binary_big_endian. The `vertex` element must have scalar x, y, z of any
/// numeric type; a `face` element, if present, contributes its list property
/// `vertex_indices` (or `vertex_index`, or else its first list) of any count
/// and index types, fan-triangulated. Other elements and properties are
/// skipped; other scalar vertex properties are returned by name. Throws
/// ParseError(name, line, reason) for header and ascii body errors and
/// ParseError(name, 0, "byte offset N: reason") for binary bodies; nothing
/// partial is returned. Element counts the rest of the file cannot hold are
/// refused (at their header line) before anything is allocated; a binary
/// element without properties takes no bytes. Data after the last element
/// is refused (in ascii, blank text is allowed).
inline PlyContent read_ply(std::istream& in, const std::string& name) {
  return detail::parse_ply(detail::read_all(in, name), name, true);
}

/// Reads the PLY file at `path` (see the stream overload).
inline PlyContent read_ply(const std::string& path) { return detail::parse_ply(detail::read_file(path), path, true); }

namespace detail {
inline TriangleMesh ply_to_mesh(PlyContent c, const std::string& name) {
  if (c.triangles.cols() == 0) throw ParseError(name, 0, "PLY file has no faces (a point cloud, not a mesh)");
  TriangleMesh m;
  m.vertices = std::move(c.vertices);
  m.triangles = std::move(c.triangles);
  return m;
}
}  // namespace detail

/// Loads a PLY triangle mesh from `in` (see read_ply); a file without faces
/// is a ParseError. Coordinates stay in file units.
inline TriangleMesh load_ply(std::istream& in, const std::string& name) {
  return detail::ply_to_mesh(detail::parse_ply(detail::read_all(in, name), name, false), name);
}

/// Loads the PLY mesh file at `path` (see the stream overload).
inline TriangleMesh load_ply(const std::string& path) {
  return detail::ply_to_mesh(detail::parse_ply(detail::read_file(path), path, false), path);
}

}  // namespace iclap
