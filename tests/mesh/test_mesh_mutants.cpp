// SPDX-License-Identifier: MIT
// What a mutation pass over the mesh geometry found unpinned, checked against
// values worked out by hand: closest points on a triangle's edges, the face
// and side a placed object rests on, center_on_table, orient_outward on a
// mesh without volume, and the count a too-fine sampling refusal states.

#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "iclap/mesh/mesh.hpp"
#include "../support/errors.hpp"

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

TEST_CASE("mesh mutants: closest point on a triangle's edges, worked by hand") {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  auto closest = [&](const Eigen::Vector3d& p) { return iclap::MeshBvh::closest_on_triangle(p, a, b, c); };
  // Off each edge, and above the face: the foot of the perpendicular.
  CHECK(closest({0.5, -1, 0.25}).isApprox(Eigen::Vector3d(0.5, 0, 0)));   // edge ab
  CHECK(closest({-1, 1.5, -0.5}).isApprox(Eigen::Vector3d(0, 1.5, 0)));   // edge ac
  CHECK(closest({2.5, 1, 0.3}).isApprox(Eigen::Vector3d(1.75, 0.25, 0)));  // edge bc: (2.5, 1) - 0.75 (1, 1)
  CHECK(closest({0.5, 0.25, 3}).isApprox(Eigen::Vector3d(0.5, 0.25, 0)));  // inside
  CHECK(closest({-1, -1, 0}) == a);
  CHECK(closest({3, -1, 0}) == b);
  CHECK(closest({-1, 3, 0}) == c);
}

TEST_CASE("mesh mutants: placement rests a pyramid on its base, base down, centred") {
  // Square pyramid (base diagonal 0.1, height 0.03): its centre of mass is
  // h/4 above the base, lower than above any side face, so it rests on the
  // base (area 2 r^2 = 0.005) with the apex up.
  auto pyramid = iclap::make_frustum(0.05, 0.0, 0.03, 4);
  Eigen::Affine3d T = Eigen::Affine3d::Identity();
  T.linear() = Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(5, -7, 2);
  iclap::transform_mesh(pyramid, T);
  const auto placed = iclap::place_on_table(pyramid);
  CHECK(placed.stable);
  CHECK(placed.resting_face_area == doctest::Approx(0.005));
  const auto b = iclap::mesh_bounds(placed.mesh);
  CHECK(std::abs(b.min().z()) < 1e-12);
  CHECK(b.sizes().z() == doctest::Approx(0.03));
  CHECK(iclap::mass_centroid(placed.mesh).z() == doctest::Approx(0.0075));
  int on_table = 0;
  for (iclap::Index v = 0; v < placed.mesh.vertex_count(); ++v) on_table += std::abs(placed.mesh.vertices(2, v)) < 1e-12;
  CHECK(on_table == 5);  // the base ring and its centre (the lathe's pole)
}

TEST_CASE("mesh mutants: center_on_table centres the bounds and puts the lowest point on z = 0") {
  const auto box = iclap::transformed(iclap::make_box({0.2, 0.1, 0.04}), Eigen::Affine3d(Eigen::Translation3d(3, -2, 1)));
  const auto placed = iclap::center_on_table(box);
  CHECK(placed.stable);
  const auto b = iclap::mesh_bounds(placed.mesh);
  CHECK(b.min().isApprox(Eigen::Vector3d(-0.1, -0.05, 0)));
  CHECK(b.max().isApprox(Eigen::Vector3d(0.1, 0.05, 0.04)));
  for (iclap::Index v = 0; v < box.vertex_count(); ++v)
    CHECK((placed.T_table_mesh * Eigen::Vector3d(box.vertices.col(v)) - placed.mesh.vertices.col(v)).norm() < 1e-12);
}

TEST_CASE("mesh mutants: orient_outward leaves a mesh of zero signed volume alone") {
  // A two-sided sheet (a triangle and its reverse) encloses nothing: no side is outward.
  iclap::TriangleMesh sheet;
  sheet.vertices.resize(3, 3);
  sheet.vertices << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  sheet.triangles.resize(3, 2);
  sheet.triangles << 0, 0, 1, 2, 2, 1;
  REQUIRE(iclap::signed_volume(sheet) == 0.0);
  const Eigen::Matrix3Xi before = sheet.triangles;
  CHECK_FALSE(iclap::orient_outward(sheet));
  CHECK(sheet.triangles == before);
}

TEST_CASE("mesh mutants: sample_surface's quick refusal states a count close to the real one") {
  // The quick bound (rows x half the longest edge per triangle) is about the
  // ideal 1.1547 area / spacing^2: a refusal says how far off the spacing is.
  const iclap::TriangleMesh box = iclap::make_box({0.05, 0.03, 0.02});
  const std::string what = iclap::test::what_of([&] { (void)iclap::sample_surface(box, 1e-6); });
  const std::string lead = "would take at least ";
  const std::size_t at = what.find(lead);
  REQUIRE(at != std::string::npos);
  const double at_least = std::stod(what.substr(at + lead.size()));
  const double ideal = 1.1547 * iclap::surface_area(box) / 1e-12;
  CHECK(at_least >= 0.99 * ideal);
  CHECK(at_least <= 1.3 * ideal);
}

TEST_CASE("mesh mutants: a resting face merged from tilted hull triangles points down along their area-weighted normal") {
  // Bottom: triangle ABC (area 0.02) in z = 0 and the thin ACD (area 0.005)
  // whose corner D is raised 0.9 mm, tilting it about 1.5 degrees (under the
  // 2 degree merge angle): one resting face. Top: a smaller square, so the
  // centre of mass is nearer the bottom.
  const Eigen::Vector3d A(-0.1, -0.1, 0), B(0.1, -0.1, 0), C(0.1, 0.1, 0), D(-0.1, -0.05, 0.0009);
  Eigen::Matrix3Xd pts(3, 8);
  pts << A, B, C, D, Eigen::Vector3d(-0.05, -0.05, 0.05), Eigen::Vector3d(0.05, -0.05, 0.05),
      Eigen::Vector3d(0.05, 0.05, 0.05), Eigen::Vector3d(-0.05, 0.05, 0.05);
  const iclap::TriangleMesh solid = iclap::convex_hull(pts);
  const Eigen::Vector3d n_abc(0, 0, -1);
  const Eigen::Vector3d n_acd = (D - A).cross(C - A).normalized();  // outward: down and towards -x, +y
  REQUIRE(n_acd.z() < 0);
  REQUIRE(std::acos(n_acd.dot(n_abc)) < 2.0 * kPi / 180);
  REQUIRE(std::acos(n_acd.dot(n_abc)) > 1.0 * kPi / 180);
  const Eigen::Vector3d down = (0.02 * n_abc + 0.5 * (D - A).cross(C - A).norm() * n_acd).normalized();
  const auto placed = iclap::place_on_table(solid);
  CHECK(placed.stable);
  CHECK(placed.resting_face_area == doctest::Approx(0.025));
  // The face's area-weighted normal is turned onto -z (the plain mean of the
  // two normals would be tilted twice as far).
  CHECK((placed.T_table_mesh.linear() * down - Eigen::Vector3d(0, 0, -1)).norm() < 1e-9);
}

TEST_CASE("mesh mutants: placement breaks a tie in height towards the larger face") {
  // An equilateral prism of side s and length s / sqrt(3): its centre of
  // mass is s / (2 sqrt(3)) from each side face and from each end, so every
  // pose is as low; a side (s^2 / sqrt(3)) is larger than an end
  // (sqrt(3) s^2 / 4), so it lies on a side.
  const double s = 0.06, length = s / std::sqrt(3.0);
  const auto prism = iclap::make_extrusion({{0, 0}, {s, 0}, {s / 2, s * std::sqrt(3.0) / 2}}, 0, length);
  const auto placed = iclap::place_on_table(prism);
  CHECK(placed.stable);
  CHECK(placed.resting_face_area == doctest::Approx(s * length));
  CHECK(iclap::mesh_bounds(placed.mesh).sizes().z() == doctest::Approx(s * std::sqrt(3.0) / 2));
}

TEST_CASE("mesh mutants: make_extrusion names the first fault of an outline that touches itself") {
  using V = std::vector<Eigen::Vector2d>;
  auto outline_error = [](const V& outline) {
    return iclap::test::what_of([&] { (void)iclap::make_extrusion(outline, 0, 1); });
  };
  // A triangle has no two edges apart, so only the checks of points and
  // edges in a row see its repeated point; without the check of two points
  // in a row it was called a fold-back.
  CHECK(outline_error({{0, 0}, {1, 0}, {1, 0}}) == "outline: points 1 and 2 coincide: not a simple polygon");
  // A zero-width spike at point 0, between the closing edge 6 and edge 0:
  // the edges are named smaller first, as elsewhere.
  CHECK(outline_error({{3, 1}, {2.5, 1}, {2, 2}, {0, 2}, {0, 0}, {2, 0}, {2, 1}}) ==
        "outline: edges 0 and 6 fold back on each other: not a simple polygon");
  // The bow-tie of test_primitives started at another point: its crossing
  // is between edge 1 and the closing edge 3, which is compared with every
  // edge but its neighbours 0 and 2.
  CHECK(outline_error({{2, 2}, {2, 0}, {0, 1}, {0, 0}}) == "outline: edges 1 and 3 cross: not a simple polygon");
  // Edges 0 and 4 overlap along y = 0, each with one end on the other: the
  // end of edge 4 on edge 0 is found first (each pair of edges looks for
  // the other's start, then its end, on the first, then the reverse).
  CHECK(outline_error({{0, 0}, {2, 0}, {2, 2}, {-1, 2}, {-1, 0}, {1, 0}, {1, -1}, {0, -1}}) ==
        "outline: point 5 lies on edge 0: not a simple polygon");
  // Edge 0 inside edge 4: both its points lie on it; the first is named.
  CHECK(outline_error({{0, 0}, {1, 0}, {1, 1}, {3, 1}, {2, 0}, {-1, 0}, {-1, -1}, {0, -1}}) ==
        "outline: point 0 lies on edge 4: not a simple polygon");
  // Point 0 on edge 4, edge 0 leaving it to the right of edge 4 (cross
  // product < 0) while edge 4's ends are on both sides of edge 0: a touch,
  // not a crossing (crossing needs both of an edge's ends strictly apart).
  CHECK(outline_error({{0, 0}, {1, 2}, {3, 2}, {3, -1}, {2, 0}, {-2, 0}, {-2, -3}, {1, -3}}) ==
        "outline: point 0 lies on edge 4: not a simple polygon");
}
