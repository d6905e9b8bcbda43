// SPDX-License-Identifier: MIT
#pragma once

// Wavefront OBJ loader (geometry only).

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/mesh/io_common.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

namespace detail {

inline TriangleMesh parse_obj(std::string_view text, const std::string& name) {
  text = without_utf8_bom(text);
  std::vector<double> v;  // x,y,z triples
  std::vector<int> tri;   // index triples
  std::vector<std::pair<std::int64_t, std::size_t>> forward;  // (index, line) defined later
  std::vector<int> poly;
  LineCursor lines(text);
  std::string_view line;
  while (lines.next(line)) {
    std::string_view rest = line;
    const std::string_view key = next_token(rest);
    if (key == "v") {
      for (int k = 0; k < 3; ++k) {
        const std::string_view tok = next_token(rest);
        double x = 0;
        if (tok.empty())
          throw ParseError(name, lines.line_number(), "vertex needs three coordinates x y z");
        if (!token_to_double(tok, x))
          throw ParseError(name, lines.line_number(),
                           "vertex coordinate " + show_token(tok) + " is not a finite number");
        v.push_back(x);
      }
      // An optional w or vertex colour (r g b, or w r g b) follows; ignored,
      // but it must be numbers (a CR-only file is one long 'v' line).
      for (int k = 0; k < 4; ++k) {
        const std::string_view tok = next_token(rest);
        if (tok.empty()) break;
        double ignored = 0;
        if (!token_to_double(tok, ignored))
          throw ParseError(name, lines.line_number(),
                           "unexpected " + show_token(tok) +
                               " after the vertex's x y z (only a w or a colour may follow; a file with "
                               "CR-only line breaks reads as one line)");
      }
      expect_line_end(rest, name, lines.line_number(), "the vertex's x y z and up to 4 more numbers (w, colour)");
    } else if (key == "f") {
      poly.clear();
      const std::int64_t defined = static_cast<std::int64_t>(v.size() / 3);
      for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) {
        const std::string_view vi = tok.substr(0, tok.find('/'));  // v, v/vt, v//vn, v/vt/vn
        std::int64_t i = 0;
        if (!token_to_int64(vi, i))
          throw ParseError(name, lines.line_number(), "face vertex " + show_token(tok) + " is not an index");
        if (i == 0)
          throw ParseError(name, lines.line_number(), "face vertex index 0 (OBJ indices start at 1)");
        std::int64_t zero_based = i > 0 ? i - 1 : defined + i;
        if (zero_based < 0)
          throw ParseError(name, lines.line_number(),
                           "relative face vertex index " + std::to_string(i) + " reaches before the first vertex (" +
                               std::to_string(defined) + " defined so far)");
        if (zero_based > INT32_MAX - 1)
          throw ParseError(name, lines.line_number(), "face vertex index " + std::to_string(i) + " is too large");
        if (zero_based >= defined) forward.push_back({zero_based, lines.line_number()});
        poly.push_back(static_cast<int>(zero_based));
      }
      if (poly.size() < 3)
        throw ParseError(name, lines.line_number(),
                         "face has " + std::to_string(poly.size()) + " vertices, needs at least 3");
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) {  // fan
        tri.push_back(poly[0]);
        tri.push_back(poly[k]);
        tri.push_back(poly[k + 1]);
      }
    }
    // Everything else (vt, vn, vp, mtllib, usemtl, o, g, s, l, p, #) is ignored.
  }
  const std::int64_t nv = static_cast<std::int64_t>(v.size() / 3);
  for (const auto& f : forward)
    if (f.first >= nv)
      throw ParseError(name, f.second,
                       "face vertex index " + std::to_string(f.first + 1) + " is out of range (" +
                           std::to_string(nv) + " vertices in the file)");
  if (tri.empty()) throw ParseError(name, 0, "no faces (f lines) in the file");
  TriangleMesh mesh;
  mesh.vertices = Eigen::Map<const Eigen::Matrix3Xd>(v.data(), 3, static_cast<Index>(nv));
  mesh.triangles = Eigen::Map<const Eigen::Matrix3Xi>(tri.data(), 3, static_cast<Index>(tri.size() / 3));
  return mesh;
}

}  // namespace detail

/// Loads the geometry of a Wavefront OBJ from `in` (`name` for errors): `v`
/// lines (x y z; up to 4 numbers after them, a w or a colour, are ignored)
/// and `f` lines (`v`, `v/vt`, `v//vn` or `v/vt/vn`: the first index is
/// used; negative indices count back from the last vertex defined; polygons
/// are fan-triangulated). Every other statement (vt, vn, mtllib, usemtl, o,
/// g, s, l, comments) is ignored; a UTF-8 byte-order mark is skipped.
/// Coordinates stay in file units. Throws ParseError(name, line, reason) for
/// a malformed number, anything else on a `v` line, an index out of range or
/// a face with fewer than 3 vertices, and ParseError(name, 0, ...) for a file without
/// faces; nothing partial is returned. O(file size).
inline TriangleMesh load_obj(std::istream& in, const std::string& name) {
  return detail::parse_obj(detail::read_all(in, name), name);
}

/// Loads the OBJ file at `path` (see the stream overload); IoError if it
/// cannot be opened.
inline TriangleMesh load_obj(const std::string& path) {
  return detail::parse_obj(detail::read_file(path), path);
}

}  // namespace iclap
