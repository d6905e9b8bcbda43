// SPDX-License-Identifier: MIT
#pragma once

// STL loader (binary and ASCII).

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/core/utf8.hpp"
#include "iclap/mesh/io_common.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap {

namespace detail {

/// Merges bit-identical vertices (STL stores each triangle's corners).
class VertexWelder {
 public:
  int add(double x, double y, double z) {
    // -0 and +0 are the same point.
    const std::array<double, 3> p = {x == 0 ? 0.0 : x, y == 0 ? 0.0 : y, z == 0 ? 0.0 : z};
    std::array<std::uint64_t, 3> key;
    std::memcpy(key.data(), p.data(), sizeof key);
    const auto it = index_.emplace(key, static_cast<int>(coords_.size() / 3));
    if (it.second) coords_.insert(coords_.end(), p.begin(), p.end());
    return it.first->second;
  }
  const std::vector<double>& coords() const noexcept { return coords_; }

 private:
  struct Hash {
    std::size_t operator()(const std::array<std::uint64_t, 3>& k) const noexcept {
      std::uint64_t h = 0x9E3779B97F4A7C15ull;
      for (auto w : k) {
        h ^= w + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
      }
      return static_cast<std::size_t>(h ^ (h >> 31));
    }
  };
  std::unordered_map<std::array<std::uint64_t, 3>, int, Hash> index_;
  std::vector<double> coords_;
};

inline std::uint32_t read_le_u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

inline float read_le_f32(const unsigned char* p) {
  const std::uint32_t bits = read_le_u32(p);
  float f = 0;
  std::memcpy(&f, &bits, 4);
  return f;
}

inline TriangleMesh finish_welded(const VertexWelder& w, const std::vector<int>& tri) {
  TriangleMesh mesh;
  mesh.vertices = Eigen::Map<const Eigen::Matrix3Xd>(w.coords().data(), 3,
                                                     static_cast<Index>(w.coords().size() / 3));
  mesh.triangles = Eigen::Map<const Eigen::Matrix3Xi>(tri.data(), 3, static_cast<Index>(tri.size() / 3));
  return mesh;
}

inline TriangleMesh parse_stl_binary(std::string_view data, const std::string& name) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  const std::uint32_t n = read_le_u32(bytes + 80);
  VertexWelder weld;
  std::vector<int> tri;
  tri.reserve(std::size_t{3} * n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const std::size_t at = 84 + std::size_t{50} * t;
    for (int k = 0; k < 3; ++k) {
      const std::size_t vat = at + 12 + 12 * static_cast<std::size_t>(k);
      double c[3];
      for (int j = 0; j < 3; ++j) {
        c[j] = read_le_f32(bytes + vat + 4 * static_cast<std::size_t>(j));
        if (!std::isfinite(c[j]))
          throw ParseError(name, 0,
                           "byte offset " + std::to_string(vat + 4 * static_cast<std::size_t>(j)) +
                               ": triangle " + std::to_string(t) + " has a non-finite coordinate");
      }
      tri.push_back(weld.add(c[0], c[1], c[2]));
    }
  }
  if (tri.empty()) throw ParseError(name, 0, "binary STL holds no triangles");
  return finish_welded(weld, tri);
}

/// Whether `t` can be a component of a facet normal, which the reader
/// ignores: a number, NaN or an infinity as from_chars spells them ("nan",
/// "-inf"), or as old Windows C libraries printed them ("1.#QNAN",
/// "-1.#IND", "1.#INF"; degenerate facets of some exporters carry these).
/// Words such as "banana" are not.
inline bool stl_normal_component(std::string_view t) {
  if (!strip_plus(t)) return false;
  double v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if ((r.ec == std::errc() || r.ec == std::errc::result_out_of_range) && r.ptr == t.data() + t.size()) return true;
  for (std::string_view special : {"#QNAN", "#SNAN", "#IND", "#INF"}) {
    const std::size_t at = t.find(special);
    if (at == std::string_view::npos) continue;
    std::string_view mantissa = t.substr(0, at), digits = t.substr(at + special.size());
    if (!mantissa.empty() && mantissa.front() == '-') mantissa.remove_prefix(1);
    if (mantissa != "1.") return false;
    return digits.find_first_not_of("0123456789") == std::string_view::npos;
  }
  return false;
}

inline TriangleMesh parse_stl_ascii(std::string_view text, const std::string& name) {
  VertexWelder weld;
  std::vector<int> tri, loop;
  LineCursor lines(text);
  std::string_view line;
  bool in_solid = false, in_facet = false, in_loop = false;
  std::size_t loop_line = 0;
  while (lines.next(line)) {
    std::string_view rest = line;
    const std::string_view key = next_token(rest);
    const std::size_t ln = lines.line_number();
    if (key.empty()) continue;
    if (key == "solid") {
      if (in_solid) throw ParseError(name, ln, "'solid' inside a solid (missing 'endsolid')");
      in_solid = true;
    } else if (key == "endsolid") {
      if (!in_solid || in_facet) throw ParseError(name, ln, "unexpected 'endsolid'");
      in_solid = false;
    } else if (key == "facet") {
      if (!in_solid || in_facet) throw ParseError(name, ln, "unexpected 'facet'");
      if (next_token(rest) != "normal") throw ParseError(name, ln, "expected 'facet normal NX NY NZ'");
      for (int k = 0; k < 3; ++k) {  // checked, then ignored: the normal is recomputed from the vertices
        const std::string_view tok = next_token(rest);
        if (!stl_normal_component(tok))
          throw ParseError(name, ln,
                           tok.empty() ? std::string("facet normal needs three components")
                                       : "facet normal component " + show_token(tok) + " is not a number");
      }
      expect_line_end(rest, name, ln, "the facet normal");
      in_facet = true;
    } else if (key == "outer") {
      if (!in_facet || in_loop || next_token(rest) != "loop")
        throw ParseError(name, ln, "expected 'outer loop' inside a facet");
      expect_line_end(rest, name, ln, "'outer loop'");
      in_loop = true;
      loop_line = ln;
      loop.clear();
    } else if (key == "vertex") {
      if (!in_loop) throw ParseError(name, ln, "'vertex' outside 'outer loop'");
      double c[3];
      for (double& x : c) {
        const std::string_view tok = next_token(rest);
        if (!token_to_double(tok, x))
          throw ParseError(name, ln,
                           tok.empty() ? std::string("vertex needs three coordinates")
                                       : "vertex coordinate " + show_token(tok) + " is not a finite number");
      }
      expect_line_end(rest, name, ln, "the vertex's three coordinates");
      loop.push_back(weld.add(c[0], c[1], c[2]));
    } else if (key == "endloop") {
      if (!in_loop) throw ParseError(name, ln, "unexpected 'endloop'");
      expect_line_end(rest, name, ln, "'endloop'");
      if (loop.size() < 3)
        throw ParseError(name, loop_line, "facet loop has " + std::to_string(loop.size()) + " vertices, needs 3");
      for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
        tri.push_back(loop[0]);
        tri.push_back(loop[k]);
        tri.push_back(loop[k + 1]);
      }
      in_loop = false;
    } else if (key == "endfacet") {
      if (!in_facet || in_loop) throw ParseError(name, ln, "unexpected 'endfacet'");
      expect_line_end(rest, name, ln, "'endfacet'");
      in_facet = false;
    } else {
      throw ParseError(name, ln, "unknown ASCII STL keyword " + show_token(key));
    }
  }
  if (in_loop || in_facet) throw ParseError(name, lines.line_number(), "file ends inside a facet");
  // A file cut between two facets (a copy or a download cut short) would
  // otherwise load as a smaller mesh.
  if (in_solid)
    throw ParseError(name, lines.line_number(), "file ends inside a solid (no 'endsolid': is it cut short?)");
  if (tri.empty()) throw ParseError(name, 0, "ASCII STL holds no facets");
  return finish_welded(weld, tri);
}

/// True for a NUL or a control character other than white space: a byte no
/// text file holds (bytes above 126 may be UTF-8 in a solid's name).
inline bool is_binary_byte(unsigned char c) {
  return c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v');
}

inline bool looks_like_ascii_stl(std::string_view data) {
  std::size_t i = 0;
  while (i < data.size() && is_space(data[i])) ++i;
  if (!starts_with(data.substr(i), "solid")) return false;
  for (char ch : data) {
    const auto c = static_cast<unsigned char>(ch);
    if (is_binary_byte(c) || c > 126) return false;
  }
  return data.find("endsolid") != std::string_view::npos || data.find("facet") != std::string_view::npos;
}

inline TriangleMesh parse_stl(std::string_view data, const std::string& name) {
  // Binary files may start with "solid" too (many CAD exporters do), so the
  // size is the real test: 84 bytes + 50 per triangle announced at byte 80.
  const bool size_fits = data.size() >= 84 &&
                         data.size() == 84 + std::uint64_t{50} * read_le_u32(reinterpret_cast<const unsigned char*>(data.data()) + 80);
  if (size_fits && !looks_like_ascii_stl(data)) return parse_stl_binary(data, name);
  // ASCII, after a UTF-8 byte-order mark if an editor wrote one (as load_obj).
  const std::string_view text = without_utf8_bom(data);
  std::size_t i = 0;
  while (i < text.size() && is_space(text[i])) ++i;
  // A file starting with "solid" that holds a byte no text holds is a
  // binary STL whose size is wrong (the ASCII parser said "cut short?" or
  // named a keyword of binary garbage).
  std::size_t binary_at = data.size();
  if (data.size() >= 84)
    for (std::size_t k = 0; k < data.size(); ++k)
      if (is_binary_byte(static_cast<unsigned char>(data[k]))) {
        binary_at = k;
        break;
      }
  const bool solid = starts_with(text.substr(i), "solid");
  if (solid && binary_at == data.size()) return parse_stl_ascii(text, name);
  if (data.size() < 84)
    throw ParseError(name, 0, "not an STL file: " + std::to_string(data.size()) +
                                  " bytes, too short for binary STL and no 'solid' keyword");
  const std::uint32_t n = read_le_u32(reinterpret_cast<const unsigned char*>(data.data()) + 80);
  throw ParseError(name, 0,
                   "byte offset 80: binary STL announces " + std::to_string(n) + " triangles (" +
                       std::to_string(84 + std::uint64_t{50} * n) + " bytes) but the file has " +
                       std::to_string(data.size()) + " bytes; not ASCII STL either (" +
                       (solid ? "byte offset " + std::to_string(binary_at) + " is not text"
                              : std::string("no 'solid'")) +
                       ")");
}

}  // namespace detail

/// Loads an STL from `in` (`name` for errors), binary or ASCII. The format is
/// told by size, not by the first bytes: a file whose size is 84 + 50 x (the
/// triangle count at byte 80) is binary even when its header starts with
/// "solid" (as many CAD exporters write), unless it is plain text with STL
/// keywords. A file of another size is ASCII if it starts with "solid" and
/// holds no NUL or control byte (other than white space); else, from 84
/// bytes on, it gets the binary size error. An ASCII file may start with a UTF-8 byte-order mark.
/// Bit-identical corners are merged into shared vertices; facet
/// normals in the file are ignored (winding order defines the normal).
/// Throws ParseError(name, line, reason) for ASCII errors and ParseError(name,
/// 0, "byte offset N: ...") for binary ones; nothing partial is returned.
inline TriangleMesh load_stl(std::istream& in, const std::string& name) {
  return detail::parse_stl(detail::read_all(in, name), name);
}

/// Loads the STL file at `path` (see the stream overload).
inline TriangleMesh load_stl(const std::string& path) { return detail::parse_stl(detail::read_file(path), path); }

}  // namespace iclap
