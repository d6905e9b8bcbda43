// SPDX-License-Identifier: MIT
// What a mutation pass over the mesh loaders found unpinned: they must refuse
// a non-finite binary value, a cut or misplaced ASCII keyword, an index one
// past the last vertex, and name the argument they refuse; binary integer
// types are read with their sign.

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>

#include "iclap/mesh/load.hpp"
#include "mesh_test_util.hpp"
#include "../support/errors.hpp"

namespace {

using iclap::test::parse_outcome;

std::string obj(const std::string& text) {
  return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_obj(in, n); }, text, "m.obj");
}
std::string stl(const std::string& text) {
  return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_stl(in, n); }, text, "m.stl");
}
std::string ply(const std::string& text) {
  return parse_outcome([](std::istream& in, const std::string& n) { return iclap::read_ply(in, n); }, text, "m.ply");
}

template <typename T>
std::string le_bytes(T value) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));  // the test machines are little endian, as PLY's binary_little_endian
  return std::string(reinterpret_cast<const char*>(b), sizeof(T));
}

// A binary STL of one triangle whose corner `corner` has coordinate `axis` = `value`.
std::string binary_stl_triangle(int corner, int axis, float value) {
  std::string s(80, 'h');  // a header that does not start with "solid"
  s += le_bytes<std::uint32_t>(1);
  float v[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};  // normal, then three corners
  v[3 + 3 * corner + axis] = value;
  for (float x : v) s += le_bytes(x);
  return s + std::string(2, '\0');
}

const std::string kFacet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";
const std::string kAsciiTriangle = "ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz +
                                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                   "0 0 0\n1 0 0\n0 1 0\n";

}  // namespace

TEST_CASE("mesh mutants: OBJ forward references one past the last vertex, tabs, a byte order mark") {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // Index 4 of 3 vertices, on a face before or after the vertices: refused
  // at its line, not returned as a mesh with an index out of range.
  CHECK(obj(tri + "f 1 2 4\n") == "4: face vertex index 4 is out of range (3 vertices in the file)");
  CHECK(obj("f 1 2 4\n" + tri) == "1: face vertex index 4 is out of range (3 vertices in the file)");
  CHECK(obj("f 1 2 3\n" + tri) == "accepted");
  // Tabs separate tokens as blanks do.
  std::istringstream tabs("v\t0\t0\t0\nv 1\t0 0\nv 0 1 0\nf\t1\t2\t3\n");
  const auto m = iclap::load_obj(tabs, "t.obj");
  CHECK(m.vertices.col(1) == Eigen::Vector3d(1, 0, 0));
  CHECK(m.triangles.col(0) == Eigen::Vector3i(0, 1, 2));
  // A UTF-8 byte order mark before the first statement is not part of it.
  CHECK(obj("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") == "accepted");
  // A number is the whole token: trailing characters are not dropped.
  CHECK(obj("v 0 1.5x 0\n" + tri + "f 1 2 3\n") == "1: vertex coordinate '1.5x' is not a finite number");
}

TEST_CASE("mesh mutants: binary STL with a non-finite coordinate or no triangles is refused") {
  CHECK(stl(binary_stl_triangle(0, 0, 0.5f)) == "accepted");
  // Corner 1, y: byte 84 + 12 (normal) + 12 (corner 0) + 4 (x) = 112.
  CHECK(stl(binary_stl_triangle(1, 1, std::numeric_limits<float>::infinity())) ==
        "0: byte offset 112: triangle 0 has a non-finite coordinate");
  CHECK(stl(binary_stl_triangle(2, 2, -std::numeric_limits<float>::infinity())) ==
        "0: byte offset 128: triangle 0 has a non-finite coordinate");
  CHECK(stl(binary_stl_triangle(0, 0, std::numeric_limits<float>::quiet_NaN())) ==
        "0: byte offset 96: triangle 0 has a non-finite coordinate");
  // A header announcing no triangles: refused, not an empty mesh.
  CHECK(stl(std::string(84, '\0')) == "0: binary STL holds no triangles");
}

TEST_CASE("mesh mutants: ASCII STL keywords out of place are refused at their line") {
  CHECK(stl("solid a\n" + kFacet + "endsolid a\n") == "accepted");
  // Blanks before 'solid' are fine.
  CHECK(stl("  \tsolid a\n" + kFacet + "endsolid a\n") == "accepted");
  CHECK(stl("solid a\nendsolid a\n") == "0: ASCII STL holds no facets");
  CHECK(stl("solid a\nsolid b\n" + kFacet + "endsolid b\nendsolid a\n") ==
        "2: 'solid' inside a solid (missing 'endsolid')");
  CHECK(stl("solid a\nfacet normal 0 0 1\nendsolid a\n") == "3: unexpected 'endsolid'");
  CHECK(stl("solid a\nfacet normal 0 0 1\nvertex 0 0 0\n") == "3: 'vertex' outside 'outer loop'");
  CHECK(stl("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendfacet\n") ==
        "7: unexpected 'endfacet'");
  // -0 and +0 are one point: two facets sharing corners written both ways.
  std::istringstream in("solid a\n" + kFacet +
                        "facet normal 0 0 1\nouter loop\nvertex -0 -0 0\nvertex 0 1 -0\nvertex -1 0 0\n"
                        "endloop\nendfacet\nendsolid a\n");
  const auto m = iclap::load_stl(in, "z.stl");
  CHECK(m.triangle_count() == 2);
  CHECK(m.vertex_count() == 4);
}

TEST_CASE("mesh mutants: binary PLY refuses a non-finite value and reads signed integer types with their sign") {
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n";
  const std::string tail = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // Two float vertices, then a face that the count check needs room for.
  auto file = [&](float x1) {
    return head + kXyz + tail + le_bytes(0.f) + le_bytes(0.f) + le_bytes(0.f) + le_bytes(x1) + le_bytes(1.f) +
           le_bytes(0.f) + std::string(1, '\3') + le_bytes<std::int32_t>(0) + le_bytes<std::int32_t>(1) +
           le_bytes<std::int32_t>(1);
  };
  const std::size_t x1_at = (head + kXyz + tail).size() + 12;
  CHECK(ply(file(1.f)) == "accepted");
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    CAPTURE(bad);
    CHECK(ply(file(bad)) == "0: byte offset " + std::to_string(x1_at) + ": element 'vertex' item 1 property 'x' is not finite");
  }
  // Cut one byte short inside the last index: refused where the value
  // starts, not read past the end.
  const std::string whole = file(1.f);
  CHECK(ply(whole.substr(0, whole.size() - 1)) == "0: byte offset " + std::to_string(whole.size() - 4) +
                                                   ": file ends inside element 'face' item 0 property 'vertex_indices'");
  // char, short and int: the sign bit is a sign, little and big endian.
  const std::string typed = "element vertex 1\nproperty char x\nproperty short y\nproperty int z\nend_header\n";
  std::istringstream le("ply\nformat binary_little_endian 1.0\n" + typed + std::string("\xff\xfe\xff\xfd\xff\xff\xff", 7));
  CHECK(iclap::read_ply(le, "le.ply").vertices.col(0) == Eigen::Vector3d(-1, -2, -3));
  std::istringstream be("ply\nformat binary_big_endian 1.0\n" + typed + std::string("\xff\xff\xfe\xff\xff\xff\xfd", 7));
  CHECK(iclap::read_ply(be, "be.ply").vertices.col(0) == Eigen::Vector3d(-1, -2, -3));
}

TEST_CASE("mesh mutants: ASCII PLY body and header errors name their line") {
  CHECK(ply(kAsciiTriangle + "3 0 1 2\n") == "accepted");
  // Data after the last element, and a value missing at a line's end (it
  // used to be taken from the next line).
  CHECK(ply(kAsciiTriangle + "3 0 1 2\n5 5 5\n") == "14: extra data after the last element");
  CHECK(ply("ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz + "end_header\n0 0\n1 0 0 0\n0 1 0\n") ==
        "8: line ends inside element 'vertex' item 0 property 'z'");
  // A negative value of an unsigned type, and a negative list count of a signed one.
  CHECK(ply(kAsciiTriangle + "-3 0 1 2\n") ==
        "13: element 'face' item 0 property 'vertex_indices' count: '-3' is out of the range of its type [0, 255]");
  const std::string char_count = "ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz +
                                 "element face 1\nproperty list char int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  CHECK(ply(char_count + "3 0 1 2\n") == "accepted");
  CHECK(ply(char_count + "-1 0 1 2\n") == "13: element 'face' item 0 property 'vertex_indices': negative list count");
  // A face of two vertices.
  CHECK(ply(kAsciiTriangle + "2 0 1\n") == "13: element 'face' item 0: face has 2 vertices, needs at least 3");
  // Header: the version, a negative count, a float list count, a missing format line.
  CHECK(ply("ply\nformat ascii 2.0\n") == "2: unsupported PLY version (expected 1.0)");
  CHECK(ply("ply\nformat ascii 1.0\nelement vertex -1\n") == "3: expected 'element NAME COUNT'");
  CHECK(ply("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n") ==
        "4: list count type must be an integer type");
  CHECK(ply("ply\nelement vertex 3\n" + kXyz + "end_header\n0 0 0\n1 0 0\n0 1 0\n") ==
        "2: PLY header has no 'format' line");
  // A face element whose vertex list is not a list.
  CHECK(ply("ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz +
            "element face 1\nproperty int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0\n") ==
        "7: element 'face' has no list property of vertex indices");
}

TEST_CASE("mesh mutants: a PLY face's 'vertex_index' list is used over an earlier list") {
  // texcoord comes first; vertex_index holds the indices (as some exporters name it).
  std::istringstream in("ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz +
                        "element face 1\nproperty list uchar float texcoord\nproperty list uchar int vertex_index\n"
                        "end_header\n0 0 0\n1 0 0\n0 1 0\n2 0.5 0.5 3 2 1 0\n");
  const auto m = iclap::load_ply(in, "vi.ply");
  REQUIRE(m.triangle_count() == 1);
  CHECK(m.triangles.col(0) == Eigen::Vector3i(2, 1, 0));
}

TEST_CASE("mesh mutants: load_mesh and parse_length_unit name their argument") {
  CHECK(iclap::is_mesh_file("a/b.stl"));
  CHECK(iclap::is_mesh_file("a/b.OBJ"));
  CHECK_FALSE(iclap::is_mesh_file("a/b.stp"));
  CHECK(iclap::test::argument_of([] { iclap::load_mesh("part.step"); }) == "path");
  CHECK(iclap::test::what_of([] { iclap::load_mesh("part.step"); }) ==
        "path: 'part.step' has no mesh extension (expected .obj, .stl or .ply)");
  CHECK(iclap::test::argument_of([] { iclap::parse_length_unit("cm", "--mesh-unit"); }) == "--mesh-unit");
  CHECK(iclap::test::argument_of([] { iclap::parse_length_unit("cm"); }) == "unit");
}

