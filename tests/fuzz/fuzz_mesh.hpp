// SPDX-License-Identifier: MIT
#pragma once
// Fuzz entries for the mesh loaders (OBJ, STL, PLY), shared by the libFuzzer
// targets (fuzz_mesh_obj.cpp, fuzz_mesh_stl.cpp, fuzz_mesh_ply.cpp, built by
// tests/fuzz/run.sh) and the doctest suite (test_fuzz_corpus.cpp runs them
// on the seed corpus). The input is the file's content, as it would be on
// disk: one target per format, so that a finding is a mesh file as is.
//
// Invariants checked (std::logic_error on violation, which libFuzzer
// reports as a crash):
// - any input either loads or throws iclap::ParseError whose message starts
//   with the file name; any other exception (std::bad_alloc, an
//   InvalidArgument, ...) escapes and is a finding;
// - the error's location exists: its line is at most the input's line
//   count, and a "byte offset N" is at most the input's size;
// - a loaded mesh has triangles, finite vertices and every index in range;
// - OBJ: one vertex per `v` line, as many triangles as the fan of every `f`
//   line gives (nothing dropped silently);
// - STL: a file not starting with "solid" is binary, with as many triangles
//   as its count at byte 80 announces and a size that matches it;
// - PLY: read_ply and load_ply agree (the same error, or the same mesh;
//   load_ply refuses only a file without faces); every other vertex
//   property has one finite value per vertex.
// The fuzz_mesh_*.cpp targets also bound the heap a load may use (see
// fuzz_heap.hpp): header counts must not allocate what the bytes cannot hold.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "iclap/core/error.hpp"
#include "iclap/mesh/load.hpp"
#include "iclap/mesh/triangle_mesh.hpp"

namespace iclap::fuzz {

inline void fuzz_mesh_require(bool ok, const char* what) {
  if (!ok) throw std::logic_error(std::string("mesh loader invariant violated: ") + what);
}

/// Lines of `text` as LineCursor counts them ('\n' ends a line; an empty
/// last line is no line).
inline std::size_t fuzz_line_count(std::string_view text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n';
  return n + (!text.empty() && text.back() != '\n');
}

/// The checks every ParseError of a reader of `input` named `name` passes.
inline void fuzz_check_parse_error(const ParseError& e, const std::string& name, std::string_view input) {
  fuzz_mesh_require(std::string(e.what()).rfind(name + ":", 0) == 0, "error message names the file");
  fuzz_mesh_require(e.file() == name, "error file");
  fuzz_mesh_require(!e.reason().empty(), "error has a reason");
  // A line past the end is fine only as the line where the input ends
  // without its last line break being there.
  fuzz_mesh_require(e.line() <= fuzz_line_count(input) + 1, "error line beyond the input");
  const std::string offset = "byte offset ";
  if (e.reason().rfind(offset, 0) == 0) {
    std::size_t at = 0, i = offset.size();
    fuzz_mesh_require(i < e.reason().size() && e.reason()[i] >= '0' && e.reason()[i] <= '9', "byte offset number");
    for (; i < e.reason().size() && e.reason()[i] >= '0' && e.reason()[i] <= '9'; ++i)
      at = at * 10 + static_cast<std::size_t>(e.reason()[i] - '0');
    fuzz_mesh_require(at <= input.size(), "byte offset beyond the input");
  }
}

/// The TriangleMesh invariants (those validate_mesh checks, but for a zero
/// area, which a file may well have).
inline void fuzz_check_mesh(const TriangleMesh& m) {
  fuzz_mesh_require(m.triangles.cols() > 0, "a loaded mesh has triangles");
  fuzz_mesh_require(m.vertices.allFinite(), "vertices finite");
  fuzz_mesh_require(m.triangles.minCoeff() >= 0 && m.triangles.maxCoeff() < m.vertices.cols(),
                    "triangle indices in range");
}

/// Runs `load(stream, name)` on `input` into `out`: "" on success, else the
/// ParseError's message after checking it.
template <typename Mesh, typename Load>
std::string fuzz_load_error(std::string_view input, const std::string& name, Load load, Mesh& out) {
  std::istringstream in{std::string(input)};
  try {
    out = load(in, name);
    return {};
  } catch (const ParseError& e) {
    fuzz_check_parse_error(e, name, input);
    return e.what();
  }
}

/// fuzz_load_error, as true for a load.
template <typename Mesh, typename Load>
bool fuzz_load(std::string_view input, const std::string& name, Load load, Mesh& out) {
  return fuzz_load_error(input, name, load, out).empty();
}

inline void fuzz_mesh_obj(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  TriangleMesh m;
  if (!fuzz_load(text, "fuzz.obj", [](std::istream& in, const std::string& n) { return load_obj(in, n); }, m)) return;
  fuzz_check_mesh(m);
  // Count the v and f lines independently of the loader (a BOM is skipped).
  std::string_view rest = text.substr(text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0);
  Index vertices = 0, triangles = 0;
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    std::string_view line = rest.substr(0, end);
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
    const std::string_view key = detail::next_token(line);
    if (key == "v") ++vertices;
    if (key != "f") continue;
    Index corners = 0;
    while (!detail::next_token(line).empty()) ++corners;
    triangles += corners - 2;
  }
  fuzz_mesh_require(m.vertices.cols() == vertices, "one vertex per v line");
  fuzz_mesh_require(m.triangles.cols() == triangles, "a fan of triangles per f line");
}

inline void fuzz_mesh_stl(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  TriangleMesh m;
  if (!fuzz_load(bytes, "fuzz.stl", [](std::istream& in, const std::string& n) { return load_stl(in, n); }, m)) return;
  fuzz_check_mesh(m);
  // (An ASCII file may start with a UTF-8 byte-order mark.)
  std::size_t i = bytes.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  while (i < size && detail::is_space(bytes[i])) ++i;
  if (bytes.substr(i, 5) == "solid") return;  // ASCII, or binary whose header starts with "solid"
  fuzz_mesh_require(size >= 84, "binary STL of at least 84 bytes");
  const std::uint32_t n = detail::read_le_u32(data + 80);
  fuzz_mesh_require(size == 84 + std::uint64_t{50} * n, "binary STL size matches its count");
  fuzz_mesh_require(static_cast<std::uint64_t>(m.triangles.cols()) == n, "binary STL triangle count");
  fuzz_mesh_require(static_cast<std::uint64_t>(m.vertices.cols()) <= std::uint64_t{3} * n, "binary STL vertices");
}

inline void fuzz_mesh_ply(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz.ply";
  PlyContent c;
  const std::string read_error =
      fuzz_load_error(bytes, name, [](std::istream& in, const std::string& n) { return read_ply(in, n); }, c);
  TriangleMesh m;
  const std::string load_error =
      fuzz_load_error(bytes, name, [](std::istream& in, const std::string& n) { return load_ply(in, n); }, m);
  if (!read_error.empty()) {
    fuzz_mesh_require(load_error == read_error, "read_ply and load_ply refuse a file alike");
    return;
  }
  const Index nv = c.vertices.cols();
  fuzz_mesh_require(c.vertices.allFinite(), "PLY vertices finite");
  fuzz_mesh_require(c.triangles.size() == 0 || (c.triangles.minCoeff() >= 0 && c.triangles.maxCoeff() < nv),
                    "PLY triangle indices in range");
  for (const auto& p : c.vertex_properties) {
    fuzz_mesh_require(p.first != "x" && p.first != "y" && p.first != "z", "x, y, z are no other property");
    fuzz_mesh_require(static_cast<Index>(p.second.size()) == nv, "one value of each vertex property per vertex");
    for (double v : p.second) fuzz_mesh_require(std::isfinite(v), "vertex property values finite");
  }
  if (c.triangles.cols() == 0) {
    fuzz_mesh_require(load_error.rfind(name + ":0: PLY file has no faces", 0) == 0, "load_ply refuses a point cloud");
    return;
  }
  fuzz_mesh_require(load_error.empty(), "load_ply loads what read_ply reads");
  fuzz_check_mesh(m);
  fuzz_mesh_require(m.vertices == c.vertices && m.triangles == c.triangles, "read_ply and load_ply agree");
}

}  // namespace iclap::fuzz
