// SPDX-License-Identifier: MIT
// Mesh loaders on small fixtures of every format and encoding, malformed
// fixtures rejected with their location.

#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "iclap/mesh/load.hpp"
#include "iclap/mesh/triangle_mesh.hpp"
#include "mesh_test_util.hpp"

using iclap::test::parse_outcome;

namespace {

std::string fixture(const std::string& name) { return std::string(ICLAP_TEST_FIXTURES) + "/mesh/" + name; }

// Every valid fixture is the box [0,2] x [0,1] x [0,0.5], outward normals.
void check_box(const iclap::TriangleMesh& m, iclap::Index vertices) {
  CHECK(m.vertex_count() == vertices);
  CHECK(m.triangle_count() == 12);
  CHECK_NOTHROW(iclap::validate_mesh(m));
  CHECK(iclap::signed_volume(m) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(iclap::surface_area(m) == doctest::Approx(7.0).epsilon(1e-12));
  const auto box = iclap::mesh_bounds(m);
  CHECK(box.min().isApprox(Eigen::Vector3d(0, 0, 0)));
  CHECK(box.max().isApprox(Eigen::Vector3d(2, 1, 0.5)));
  CHECK(iclap::mass_centroid(m).isApprox(Eigen::Vector3d(1, 0.5, 0.25), 1e-12));
}

void check_rejected(const std::string& file, std::size_t line, const std::string& reason_part) {
  CAPTURE(file);
  try {
    iclap::load_mesh(fixture(file));
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == fixture(file));
    CHECK(e.line() == line);
    CHECK_MESSAGE(e.reason().find(reason_part) != std::string::npos, e.what());
  }
}

}  // namespace

TEST_CASE("mesh io: OBJ with v/vt/vn, v//vn, v/vt, quads, negative indices, CRLF") {
  check_box(iclap::load_mesh(fixture("box_quads.obj")), 8);
  // Polygons are fanned from their first vertex.
  std::istringstream in("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0 1.0\nf 1 2 3 5 4\n");
  const auto m = iclap::load_obj(in, "pentagon");
  REQUIRE(m.triangle_count() == 3);
  CHECK(m.triangles.col(0) == Eigen::Vector3i(0, 1, 2));
  CHECK(m.triangles.col(1) == Eigen::Vector3i(0, 2, 4));
  CHECK(m.triangles.col(2) == Eigen::Vector3i(0, 4, 3));
}

TEST_CASE("mesh io: STL binary, binary starting with 'solid', ASCII") {
  check_box(iclap::load_mesh(fixture("box_binary.stl")), 8);
  check_box(iclap::load_mesh(fixture("box_binary_solid.stl")), 8);
  check_box(iclap::load_mesh(fixture("box_ascii.stl")), 8);
}

TEST_CASE("mesh io: PLY ascii, binary little endian, binary big endian") {
  check_box(iclap::load_mesh(fixture("box_ascii.ply")), 8);
  check_box(iclap::load_mesh(fixture("box_binary_le.ply")), 8);
  check_box(iclap::load_mesh(fixture("box_binary_be.ply")), 8);
  // Extra vertex properties come back by name with read_ply.
  const auto le = iclap::read_ply(fixture("box_binary_le.ply"));
  REQUIRE(le.vertex_properties.count("red") == 1);
  CHECK(le.vertex_properties.at("red") == std::vector<double>(8, 7.0));
  const auto be = iclap::read_ply(fixture("box_binary_be.ply"));
  CHECK(be.vertices == le.vertices);
  CHECK(be.triangles == le.triangles);
  const auto asc = iclap::read_ply(fixture("box_ascii.ply"));
  CHECK(asc.vertex_properties.at("nx") == std::vector<double>(8, 0.5));
  CHECK(asc.triangles == le.triangles);
}

TEST_CASE("mesh io: malformed files are rejected with their location") {
  check_rejected("bad_index.obj", 6, "face vertex index 9 is out of range (3 vertices");
  check_rejected("bad_number.obj", 2, "'zero' is not a finite number");
  check_rejected("bad_face.obj", 4, "face has 2 vertices");
  check_rejected("bad_ascii.stl", 5, "'nan' is not a finite number");
  check_rejected("truncated_binary.stl", 0, "byte offset 80: binary STL announces 12 triangles (684 bytes)");
  check_rejected("truncated_le.ply", 0, "byte offset");
  check_rejected("truncated_le.ply", 0, "byte offset 618: file ends inside element 'face' item 4 property 'quality'");
  check_rejected("bad_index_ascii.ply", 13, "vertex index 3 is out of range (3 vertices)");
  check_rejected("bad_header.ply", 6, "unknown PLY type 'quaternion'");
}

TEST_CASE("mesh io: more malformed input, from streams") {
  auto obj_error = [](const std::string& text) {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_obj(in, n); }, text, "s.obj");
  };
  CHECK(obj_error("v 0 0 0\nf 0 1 1\n") == "2: face vertex index 0 (OBJ indices start at 1)");
  CHECK(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n").rfind("4: relative face vertex index -4", 0) == 0);
  CHECK(obj_error("v 0 0\n").rfind("1: vertex needs three coordinates", 0) == 0);
  CHECK(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 a\n").rfind("4: face vertex 'a' is not an index", 0) == 0);
  CHECK(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n") == "0: no faces (f lines) in the file");
  // Forward references are fine when the vertex comes later.
  CHECK(obj_error("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n") == "accepted");

  auto stl_error = [](const std::string& text) {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_stl(in, n); }, text, "s.stl");
  };
  CHECK(stl_error("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid a\n")
            .rfind("3: facet loop has 2 vertices", 0) == 0);
  CHECK(stl_error("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n").rfind("4: file ends inside a facet", 0) == 0);
  CHECK(stl_error("solid a\nbanana\n").rfind("2: unknown ASCII STL keyword 'banana'", 0) == 0);
  // Cut between two facets: refused, not loaded as a smaller mesh.
  const std::string facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  CHECK(stl_error("solid a\n" + facet + "endsolid a\n") == "accepted");
  CHECK(stl_error("solid a\n" + facet) == "8: file ends inside a solid (no 'endsolid': is it cut short?)");
  CHECK(stl_error("hello").rfind("0: not an STL file", 0) == 0);

  auto ply_error = [](const std::string& text) {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_ply(in, n); }, text, "s.ply");
  };
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  CHECK(ply_error("plx\n").rfind("1: not a PLY file", 0) == 0);
  CHECK(ply_error(head + "end_header\n0 0 0\n1 0 0\n0 1 0\n").rfind("0: PLY file has no faces", 0) == 0);
  CHECK(ply_error(head + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n")
            .rfind("11: extra values after element 'vertex' item 1", 0) == 0);
  CHECK(ply_error(head + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n")
            .rfind("13: element 'face' item 0 property 'vertex_indices': '1.5' is not an integer", 0) == 0);
  CHECK(ply_error(head + "element face 1\nproperty list uchar int vertex_indices\n").rfind("8: PLY header has no 'end_header'", 0) == 0);
  CHECK(ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n")
            .rfind("3: element 'vertex' lacks a scalar property x, y or z", 0) == 0);
  CHECK(ply_error("ply\nformat binary_middle_endian 1.0\n").rfind("2: unknown PLY format", 0) == 0);
  // ASCII integers stay within their declared type, as binary bytes do (a
  // uchar of 300 or -5 was taken as written).
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  CHECK(ply_error(head + faces + "3 0 1 2\n") == "accepted");
  CHECK(ply_error(head + faces + "300 0 1 2\n")
            .rfind("13: element 'face' item 0 property 'vertex_indices' count: '300' is out of the range of its type [0, 255]", 0) == 0);
  CHECK(ply_error(head + faces + "3 0 1 99999999999\n").find("is out of the range of its type [-2147483648, 2147483647]") !=
        std::string::npos);
  // "+-1" is not -1 (from_chars after a stripped '+'), in any format.
  CHECK(ply_error(head + faces + "3 0 1 +-1\n").find("'+-1' is not an integer") != std::string::npos);
  CHECK(obj_error("v +-1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").rfind("1: ", 0) == 0);
  CHECK(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 +-1\n").rfind("4: ", 0) == 0);
  CHECK(stl_error("solid a\nfacet normal 0 0 1\nouter loop\nvertex +-1 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid a\n")
            .rfind("4: ", 0) == 0);
  CHECK(obj_error("v +1 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\n") == "accepted");
}

TEST_CASE("mesh io: ASCII STL and PLY header lines hold what their syntax allows, no more") {
  auto stl = [&](const std::string& normal, const std::string& vertex, const std::string& tail = "") {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_stl(in, n); },
                 "solid a\nfacet normal " + normal + "\nouter loop" + tail + "\nvertex " + vertex +
                     "\nvertex 1 0 0\nvertex 0 1 0\nendloop" + tail + "\nendfacet" + tail + "\nendsolid a\n",
                 "s.stl");
  };
  CHECK(stl("0 0 1", "0 0 0") == "accepted");
  // The normal is ignored, but it is three numbers: NaN and infinities as
  // exporters write them for degenerate facets are numbers, words are not.
  CHECK(stl("nan -nan inf", "0 0 0") == "accepted");
  CHECK(stl("-1.#IND00 1.#QNAN 1.#INF", "0 0 0") == "accepted");
  CHECK(stl("1e999 0 0", "0 0 0") == "accepted");
  CHECK(stl("nan banana 0", "0 0 0") == "2: facet normal component 'banana' is not a number");
  CHECK(stl("1.#banana 0 0", "0 0 0") == "2: facet normal component '1.#banana' is not a number");
  CHECK(stl("2.#IND 0 0", "0 0 0") == "2: facet normal component '2.#IND' is not a number");
  CHECK(stl("0 0", "0 0 0") == "2: facet normal needs three components");
  CHECK(stl("0 0 1 7", "0 0 0") == "2: unexpected '7' after the facet normal");
  CHECK(parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_stl(in, n); },
              "solid a\nfacet\nouter loop\n", "s.stl") == "2: expected 'facet normal NX NY NZ'");
  // Junk after the three coordinates used to be dropped silently.
  CHECK(stl("0 0 1", "0 0 0 junk") == "4: unexpected 'junk' after the vertex's three coordinates");
  CHECK(stl("0 0 1", "0 0 0 1") == "4: unexpected '1' after the vertex's three coordinates");
  CHECK(stl("0 0 1", "0 0 0", " x") == "3: unexpected 'x' after 'outer loop'");

  auto ply = [&](const std::string& text) {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_ply(in, n); }, text, "s.ply");
  };
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  auto header = [](const std::string& format, const std::string& vertex, const std::string& x, const std::string& end) {
    return "ply\n" + format + "\n" + vertex + "\n" + x +
           "\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n" + end +
           "\n";
  };
  CHECK(ply(header("format ascii 1.0", "element vertex 3", "property float x", "end_header") + body) == "accepted");
  CHECK(ply(header("format ascii 1.0 junk", "element vertex 3", "property float x", "end_header") + body) ==
        "2: unexpected 'junk' after 'format ascii 1.0'");
  CHECK(ply(header("format ascii 1.0", "element vertex 3 junk", "property float x", "end_header") + body) ==
        "3: unexpected 'junk' after 'element NAME COUNT'");
  CHECK(ply(header("format ascii 1.0", "element vertex 3", "property float x x2", "end_header") + body) ==
        "4: unexpected 'x2' after the property name 'x'");
  CHECK(ply(header("format ascii 1.0", "element vertex 3", "property float x", "end_header now") + body) ==
        "9: unexpected 'now' after 'end_header'");
  // A second vertex element (the first one's data was dropped) and a second
  // property of a name (the last one won).
  CHECK(ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement vertex 3\n") ==
        "5: a second element 'vertex' (the first at line 3): which one holds the data is ambiguous");
  CHECK(ply(header("format ascii 1.0", "element vertex 3", "property float x\nproperty double x", "end_header") + body) ==
        "5: element 'vertex' has a second property 'x'");
  CHECK(ply("ply\nformat ascii 1.0\nformat binary_little_endian 1.0\n") == "3: a second 'format' line");
}

TEST_CASE("mesh io: load_mesh picks the format by extension, units") {
  CHECK_THROWS_AS(iclap::load_mesh(fixture("make_fixtures.py")), iclap::InvalidArgument);
  CHECK_THROWS_AS(iclap::load_mesh(fixture("missing.obj")), iclap::IoError);
  CHECK_THROWS_AS(iclap::load_obj(std::string(ICLAP_TEST_FIXTURES)), iclap::IoError);
  CHECK(iclap::is_mesh_file("a/b.PLY"));
  CHECK_FALSE(iclap::is_mesh_file("a.ply/b"));
  CHECK(iclap::parse_length_unit("mm") == iclap::LengthUnit::millimetres);
  CHECK(iclap::metres_per_unit(iclap::LengthUnit::millimetres) == 1e-3);
  CHECK_THROWS_AS(iclap::parse_length_unit("cm"), iclap::InvalidArgument);
  auto m = iclap::load_mesh(fixture("box_binary_be.ply"));
  iclap::scale_mesh(m, 1e-3);
  CHECK(iclap::mesh_bounds(m).max().isApprox(Eigen::Vector3d(2e-3, 1e-3, 0.5e-3)));
}

TEST_CASE("mesh io: the shared real meshes load with their documented sizes") {
  const std::string dir = std::string(ICLAP_SHARED_DIR) + "/data/meshes/";
  if (std::string(ICLAP_SHARED_DIR).empty() || !std::ifstream(dir + "wt_pliers.ply")) {
    MESSAGE("shared meshes not available; skipped");
    return;
  }
  // Counts from SOURCES.md.
  const auto pliers = iclap::load_mesh(dir + "wt_pliers.ply");
  CHECK(pliers.triangle_count() == 15130);
  CHECK(pliers.vertex_count() == 7612);
  CHECK(iclap::signed_volume(pliers) / 1000.0 == doctest::Approx(81.15).epsilon(0.01));  // cm^3
  const auto scissors = iclap::load_mesh(dir + "ycb_037_scissors.obj");
  CHECK(scissors.triangle_count() == 16384);
  CHECK(scissors.vertex_count() == 8188);
  CHECK(iclap::signed_volume(scissors) * 1e6 == doctest::Approx(46.8).epsilon(0.01));
}

namespace {
// "LINE: reason" of the ParseError `read_ply` throws for `text`, the type
// name of any other exception, or "accepted: N vertices".
std::string ply_outcome(const std::string& text) {
  std::istringstream in(text);
  try {
    const auto c = iclap::read_ply(in, "t.ply");
    return "accepted: " + std::to_string(c.vertices.cols()) + " vertices";
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == "t.ply");
    return std::to_string(e.line()) + ": " + e.reason();
  } catch (const std::exception& e) {
    return std::string("other exception: ") + e.what();
  }
}
const std::string kTetBody = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const std::string kTetHead =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 4\nproperty list uchar int vertex_indices\n";
}  // namespace

TEST_CASE("mesh io: PLY element counts the file cannot hold are refused before reading or allocating") {
  // ascii, an element without properties and a huge count: used to loop forever.
  CHECK(ply_outcome(kTetHead + "element pad 9000000000000000000\nend_header\n" + kTetBody)
            .rfind("9: element 'pad' declares 9000000000000000000 items, more than the ", 0) == 0);
  // ... a small count of empty items is still fine, even with no lines for them at the end.
  CHECK(ply_outcome(kTetHead + "element pad 1\nend_header\n" + kTetBody) == "accepted: 4 vertices");
  CHECK(ply_outcome(kTetHead + "element pad 2\nend_header\n" + kTetBody + "\n\n") == "accepted: 4 vertices");
  // binary: an element without properties takes no bytes, whatever its count.
  const std::string bin = "ply\nformat binary_little_endian 1.0\n";
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  CHECK(ply_outcome(bin + "element pad 9000000000000000000\nelement vertex 1\n" + xyz + "end_header\n" +
                    std::string(12, '\0')) == "accepted: 1 vertices");
  // ... one with properties cannot have more items than bytes.
  CHECK(ply_outcome(bin + "element pad 9000000000000000000\nproperty uchar a\nelement vertex 1\n" + xyz +
                    "end_header\n" + std::string(12, '\0'))
            .rfind("3: element 'pad' declares 9000000000000000000 items, more than the 12 bytes", 0) == 0);
  CHECK(ply_outcome(bin + "element pad 5\nproperty list uint int idx\nelement vertex 1\n" + xyz + "end_header\n" +
                    std::string(12, '\0'))
            .rfind("3: element 'pad' declares 5 items", 0) == 0);
  // The vertex count is checked before the vertices are allocated: no
  // std::bad_alloc for 2e9 vertices, no 700 MB for 6e7 in a tiny file.
  const std::string label = "property float label\nend_header\n";
  CHECK(ply_outcome(bin + "element vertex 2000000000\n" + xyz + label)
            .rfind("3: element 'vertex' declares 2000000000 items, more than the 0 bytes", 0) == 0);
  CHECK(ply_outcome(bin + "element vertex 60000000\n" + xyz + label + std::string(64, '\0'))
            .rfind("3: element 'vertex' declares 60000000 items, more than the 64 bytes", 0) == 0);
  // The counts add up: the vertices fit alone but not with the faces after them.
  CHECK(ply_outcome(bin + "element vertex 1\n" + xyz + "element face 1\nproperty list uchar int vertex_indices\n" +
                    "end_header\n" + std::string(12, '\0'))
            .rfind("7: element 'face' declares 1 items, more than the 12 bytes", 0) == 0);
  // ascii: each item of an element with properties needs a value and a line break.
  CHECK(ply_outcome("ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "end_header\n0 0\n")
            .rfind("3: element 'vertex' declares 3 items, more than the 4 bytes", 0) == 0);
}

TEST_CASE("mesh io: an ascii PLY item needs a value and a blank or line break per property, refused before allocating") {
  // 100 properties besides x, y, z: each vertex takes at least 206 bytes, so
  // 500 vertices do not fit in the 1006 bytes of this body. Counted at 2 bytes
  // an item, they did: the reader allocated 500 x 103 values first (a 1 MB
  // file with 1000 properties made it allocate 4 GB, 8 bytes per property
  // per 2 bytes of file) and only then failed in the body.
  std::string props;
  for (int i = 0; i < 100; ++i) props += "property uchar p" + std::to_string(i) + "\n";
  std::string vertex = "0 0 0";
  for (int i = 0; i < 100; ++i) vertex += " 1";
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string body = vertex + "\n" + std::string(800, '\n');
  CHECK(ply_outcome("ply\nformat ascii 1.0\nelement vertex 500\n" + xyz + props + "end_header\n" + body) ==
        "3: element 'vertex' declares 500 items, more than the 1006 bytes after the header can hold");
  CHECK(ply_outcome("ply\nformat ascii 1.0\nelement vertex 1\n" + xyz + props + "end_header\n" + body) ==
        "accepted: 1 vertices");
  // The least an item takes: one character per value, one blank between
  // them, a line break after the last (but the file's last).
  CHECK(ply_outcome("ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "end_header\n0 0 0\n1 0 0\n0 1 0") ==
        "accepted: 3 vertices");
  CHECK(ply_outcome("ply\nformat ascii 1.0\nelement vertex 4\n" + xyz + "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0")
            .rfind("3: element 'vertex' declares 4 items, more than the 21 bytes", 0) == 0);
}

TEST_CASE("mesh io: PLY float vertex indices out of range or fractional are shown as read") {
  const std::string float_head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string where = "14: element 'face' item 0: vertex index ";
  CHECK(ply_outcome(float_head + "3 0 1 1e30\n") == where + "1e+30 is out of range (4 vertices)");
  CHECK(ply_outcome(float_head + "3 0 1 -1e30\n") == where + "-1e+30 is out of range (4 vertices)");
  CHECK(ply_outcome(float_head + "3 0 1 1.5\n") == where + "1.5 is not an integer");
  CHECK(ply_outcome(float_head + "3 0 1 -0.25\n") == where + "-0.25 is not an integer");
  CHECK(ply_outcome(float_head + "3 0 1 4\n") == where + "4 is out of range (4 vertices)");
  CHECK(ply_outcome(float_head + "3 0 1 -3\n") == where + "-3 is out of range (4 vertices)");
  CHECK(ply_outcome(float_head + "3 0 1 3\n") == "accepted: 4 vertices");
  // Binary doubles too: 2^63 used to print as -9223372036854775808.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar double vertex_indices\nend_header\n";
  bin += std::string(36, '\0');
  bin += '\3';
  for (const double v : {0.0, 1.0, 9223372036854775808.0}) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    for (int k = 0; k < 8; ++k) bin += static_cast<char>((bits >> (8 * k)) & 0xffu);  // little endian
  }
  CHECK(ply_outcome(bin).find("vertex index 9.22337e+18 is out of range (3 vertices)") != std::string::npos);
}

// --- Reproducers of defects found by helper-40's audit (session 49), fixed in the same
// session. "Happens" is what the library did before the fix.

TEST_CASE("mesh io: a binary PLY with data after its last element is refused, like ascii PLY and binary STL") {
  // The tetrahedron of kTetBody, but the header declares 3 faces while the
  // body holds 4 (an exporter's count off by one, or two files run
  // together). Expected: a ParseError (ascii PLY says "extra data after the
  // last element", binary STL refuses a size that does not match its count).
  // Happens: the binary file loads as an open mesh of 3 triangles (volume 0),
  // the fourth face dropped without a word.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 3\nproperty list uchar int vertex_indices\nend_header\n";
  const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  bin.append(reinterpret_cast<const char*>(v), sizeof v);
  const std::int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    bin += '\3';
    bin.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  const std::string outcome =
      parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_ply(in, n); }, bin, "t.ply");
  CHECK(outcome != "accepted");
  CHECK(outcome.find("extra data after the last element") != std::string::npos);
  // The same file in ascii is refused (this holds today).
  const std::string ascii_head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 3\nproperty list uchar int vertex_indices\nend_header\n";
  CHECK(ply_outcome(ascii_head + kTetBody) == "17: extra data after the last element");
}

TEST_CASE("mesh io: an ASCII STL starting with a UTF-8 byte-order mark loads like the same OBJ does") {
  // load_obj skips a UTF-8 BOM (Windows editors write one). Expected: load_stl
  // does too (or refuses naming the BOM). Happens: the file is taken for a
  // binary STL: "byte offset 80: binary STL announces 1818521189 triangles
  // (90926059534 bytes) but the file has 108 bytes; not ASCII STL either (no
  // 'solid')", although its first word after the BOM is 'solid'.
  const std::string bom = "\xEF\xBB\xBF";
  const std::string stl =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
      "endsolid t\n";
  std::istringstream obj(bom + "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  CHECK(iclap::load_obj(obj, "t.obj").triangle_count() == 1);
  const std::string outcome =
      parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_stl(in, n); }, bom + stl, "t.stl");
  CHECK(outcome == "accepted");
  CHECK(outcome.find("no 'solid'") == std::string::npos);
}

TEST_CASE("mesh io: an OBJ vertex line with a word after x y z is malformed, not silently cut") {
  // load_obj documents that a w or vertex colour after x y z is ignored, and
  // io_common.hpp's rule is that a line with more than its syntax allows is
  // malformed. Expected: ParseError at line 1 for 'junk'. Happens: accepted.
  // The visible consequence is an old-Mac OBJ with CR-only line endings: the
  // whole file is one 'v' line whose rest is ignored, refused as
  // "0: no faces (f lines) in the file" although it has an f line.
  auto obj = [](const std::string& text) {
    return parse_outcome([](std::istream& in, const std::string& n) { return iclap::load_obj(in, n); }, text, "t.obj");
  };
  CHECK(obj("v 0 0 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") == "accepted");            // w: fine
  CHECK(obj("v 0 0 0 0.5 0.5 0.5\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") == "accepted");  // colour: fine
  CHECK(obj("v 0 0 0 junk\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").rfind("1: ", 0) == 0);
  CHECK(obj("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").find("no faces") == std::string::npos);
}
