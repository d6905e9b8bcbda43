// SPDX-License-Identifier: MIT
// What a mutation pass over the primitives (primitives.hpp) found unpinned,
// checked as properties of the solids rather than copies of their vertices:
// every solid is closed and consistently outward without degenerate
// triangles, has the asked-for dimensions and the volume of its polygonal
// approximation; bad arguments are refused naming the argument and why.

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "iclap/mesh/mesh.hpp"
#include "../support/errors.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

// Area of the regular n-gon inscribed in the unit circle: the lathe's rings.
double ngon_area(int n) { return n / 2.0 * std::sin(2 * kPi / n); }

// Checks that `m` is `shells` closed, consistently oriented surfaces of
// sphere topology with outward normals and no degenerate triangle: every
// directed edge appears once and its reverse once, every vertex is used,
// V - E + F = 2 per shell, the signed volume is positive and no triangle's
// area is below 1e-9 of the mean (a pole made a tiny ring gives ~1e-17).
void check_closed_outward(const iclap::TriangleMesh& m, int shells = 1) {
  REQUIRE_NOTHROW(iclap::validate_mesh(m));
  std::map<std::pair<int, int>, int> directed;
  std::vector<int> uses(static_cast<std::size_t>(m.vertex_count()), 0);
  for (iclap::Index t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      ++directed[{m.triangles(k, t), m.triangles((k + 1) % 3, t)}];
      ++uses[static_cast<std::size_t>(m.triangles(k, t))];
    }
  int unpaired = 0;
  for (const auto& e : directed) {
    const auto reverse = directed.find({e.first.second, e.first.first});
    if (e.second != 1 || reverse == directed.end() || reverse->second != 1) ++unpaired;
  }
  CHECK(unpaired == 0);
  int unused = 0;
  for (int u : uses) unused += u == 0;
  CHECK(unused == 0);
  const auto edges = static_cast<iclap::Index>(directed.size() / 2);
  CHECK(m.vertex_count() - edges + m.triangle_count() == 2 * shells);
  CHECK(iclap::signed_volume(m) > 0);
  const double mean_area = iclap::surface_area(m) / static_cast<double>(m.triangle_count());
  int degenerate = 0;
  for (iclap::Index t = 0; t < m.triangle_count(); ++t) degenerate += 0.5 * m.area_normal(t).norm() < 1e-9 * mean_area;
  CHECK(degenerate == 0);
}

// Largest distance of a vertex from the z axis.
double max_radius(const iclap::TriangleMesh& m) { return m.vertices.topRows(2).colwise().norm().maxCoeff(); }

// Signed area (counter-clockwise positive) and perimeter of a polygon.
double polygon_area(const std::vector<Eigen::Vector2d>& p) {
  double a2 = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& a = p[i];
    const auto& b = p[(i + 1) % p.size()];
    a2 += a.x() * b.y() - b.x() * a.y();
  }
  return a2 / 2;
}
double perimeter(const std::vector<Eigen::Vector2d>& p) {
  double l = 0;
  for (std::size_t i = 0; i < p.size(); ++i) l += (p[(i + 1) % p.size()] - p[i]).norm();
  return l;
}

}  // namespace

TEST_CASE("primitives: a box is closed, outward and exactly the size asked for; bad edges are refused") {
  const Eigen::Vector3d size(0.3, 0.2, 0.1);
  const auto box = iclap::make_box(size);
  check_closed_outward(box);
  CHECK(box.triangle_count() == 12);
  const auto b = iclap::mesh_bounds(box);
  CHECK(b.min().isApprox(-size / 2));
  CHECK(b.max().isApprox(size / 2));
  CHECK(iclap::signed_volume(box) == doctest::Approx(size.prod()));
  // Every edge must be positive, not just one of them.
  CHECK(iclap::test::what_of([] { (void)iclap::make_box({1, -2, 1}); }) ==
        "size: box edges must be finite and positive, got 1 x -2 x 1");
  CHECK(iclap::test::what_of([] { (void)iclap::make_box({0, 0, 0}); }) ==
        "size: box edges must be finite and positive, got 0 x 0 x 0");
  CHECK(iclap::test::what_of([] { (void)iclap::make_box({1, 1, -1e-9}); }) ==
        "size: box edges must be finite and positive, got 1 x 1 x -1e-09");
  // An infinite edge would put infinities into the vertices.
  CHECK(iclap::test::what_of([] { (void)iclap::make_box({1, HUGE_VAL, 1}); }) ==
        "size: box edges must be finite and positive, got 1 x inf x 1");
}

TEST_CASE("primitives: cylinders and frustums are closed, outward, as long and wide as asked, with the polygon's volume") {
  // A lathe of n segments inscribes regular n-gons: a band between radii
  // r0 and r1 over a height h is a polygonal frustum of volume
  // h / 3 ngon_area(n) (r0^2 + r0 r1 + r1^2). Odd n: no symmetry hides a
  // half-turned ring.
  for (int n : {3, 7, 32}) {
    CAPTURE(n);
    const auto cyl = iclap::make_cylinder(0.4, 1.5, n);
    check_closed_outward(cyl);
    CHECK(iclap::signed_volume(cyl) == doctest::Approx(ngon_area(n) * 0.16 * 1.5).epsilon(1e-12));
    CHECK(iclap::mesh_bounds(cyl).min().z() == doctest::Approx(-0.75));
    CHECK(iclap::mesh_bounds(cyl).max().z() == doctest::Approx(0.75));
    CHECK(max_radius(cyl) == doctest::Approx(0.4));

    const double r0 = 0.3, r1 = 0.1, length = 2;
    const auto frustum = iclap::make_frustum(r0, r1, length, n);
    check_closed_outward(frustum);
    CHECK(iclap::signed_volume(frustum) ==
          doctest::Approx(length / 3 * ngon_area(n) * (r0 * r0 + r0 * r1 + r1 * r1)).epsilon(1e-12));
    CHECK(iclap::mesh_bounds(frustum).min().z() == 0.0);
    CHECK(iclap::mesh_bounds(frustum).max().z() == doctest::Approx(length));
    // Each end has the radius asked for.
    for (iclap::Index v = 0; v < frustum.vertex_count(); ++v) {
      const double r = frustum.vertices.col(v).head<2>().norm(), z = frustum.vertices(2, v);
      CHECK((r < 1e-15 || std::abs(r - (z == 0 ? r0 : r1)) < 1e-12));
    }
    // Cones either way up: the tip is a pole, a single vertex.
    for (const auto& radii : {std::pair<double, double>(0.2, 0.0), std::pair<double, double>(0.0, 0.2)}) {
      const auto cone = iclap::make_frustum(radii.first, radii.second, 0.5, n);
      check_closed_outward(cone);
      CHECK(cone.vertex_count() == n + 2);
      CHECK(iclap::signed_volume(cone) == doctest::Approx(0.5 / 3 * ngon_area(n) * 0.04).epsilon(1e-12));
    }
  }
}

TEST_CASE("primitives: spheres and capsules have every vertex on the surface and hug it to the chord error") {
  const double R = 0.7;
  for (int rings : {2, 5, 12}) {
    CAPTURE(rings);
    const auto sphere = iclap::make_sphere(R, 9, rings);
    check_closed_outward(sphere);
    for (iclap::Index v = 0; v < sphere.vertex_count(); ++v) CHECK(sphere.vertices.col(v).norm() == doctest::Approx(R));
    CHECK(iclap::mesh_bounds(sphere).min().z() == doctest::Approx(-R));
    CHECK(iclap::mesh_bounds(sphere).max().z() == doctest::Approx(R));
    // Inscribed: inside the ball, and outside the ball of radius R cos(pi /
    // (2 rings)) cos(pi / segments) that every face plane clears.
    const double inner = R * std::cos(kPi / (2 * rings)) * std::cos(kPi / 9);
    CHECK(iclap::signed_volume(sphere) < 4.0 / 3 * kPi * R * R * R);
    CHECK(iclap::signed_volume(sphere) > 4.0 / 3 * kPi * inner * inner * inner);
  }

  // Capsule: radius r about the axis segment z in [-h, h].
  const double r = 0.2, length = 0.6, h = length / 2;
  for (int cap_rings : {1, 3, 6}) {
    CAPTURE(cap_rings);
    const auto capsule = iclap::make_capsule(r, length, 11, cap_rings);
    check_closed_outward(capsule);
    auto to_axis = [&](const Eigen::Vector3d& p) {
      return (p - Eigen::Vector3d(0, 0, std::clamp(p.z(), -h, h))).norm();
    };
    for (iclap::Index v = 0; v < capsule.vertex_count(); ++v)
      CHECK(to_axis(capsule.vertices.col(v)) == doctest::Approx(r));
    CHECK(iclap::mesh_bounds(capsule).min().z() == doctest::Approx(-h - r));
    CHECK(iclap::mesh_bounds(capsule).max().z() == doctest::Approx(h + r));
    // No face cuts deeper than the chord of a cap step (pi / 2 / cap_rings)
    // around a segment step (2 pi / 11): the cylinder runs the full length.
    const double inner = r * std::cos(kPi / (4 * cap_rings)) * std::cos(kPi / 11);
    int deep = 0;
    for (iclap::Index t = 0; t < capsule.triangle_count(); ++t) {
      const Eigen::Vector3d c = (capsule.corner(t, 0) + capsule.corner(t, 1) + capsule.corner(t, 2)) / 3;
      deep += to_axis(c) < inner - 1e-12;
    }
    CHECK(deep == 0);
  }
}

TEST_CASE("primitives: make_lathe closes pole ends, skips an axis segment between two poles, refuses bad profiles") {
  // Two cylinders stacked along the axis, joined by an axis segment (two
  // poles in a row): two closed shells, nothing spanning the gap.
  const int n = 5;
  const auto twin = iclap::make_lathe({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 2}, {1, 2}, {1, 3}, {0, 3}}, n);
  check_closed_outward(twin, 2);
  CHECK(iclap::signed_volume(twin) == doctest::Approx(2 * ngon_area(n)).epsilon(1e-12));
  int in_gap = 0;
  for (iclap::Index t = 0; t < twin.triangle_count(); ++t) {
    const double z = (twin.corner(t, 0) + twin.corner(t, 1) + twin.corner(t, 2)).z() / 3;
    in_gap += z > 1 && z < 2;
  }
  CHECK(in_gap == 0);

  CHECK(iclap::test::what_of([] { (void)iclap::make_lathe({{1, 0}}, 8); }) == "profile: needs at least 2 points");
  CHECK(iclap::test::what_of([] { (void)iclap::make_lathe({{0, 0}, {1, 0}, {0, 1}}, 2); }) ==
        "segments: needs at least 3, got 2");
  CHECK(iclap::test::what_of([] { (void)iclap::make_lathe({{0, 0}, {1, 0}, {0, 1}}, 3); }) == "(no error)");
  CHECK(iclap::test::what_of([] { (void)iclap::make_lathe({{0, 0}, {-1, 0}, {0, 1}}, 8); }) ==
        "profile: radius must be >= 0, got -1 at point 1");
  CHECK(iclap::test::what_of([] { (void)iclap::make_lathe({{0, 0}, {1, 0}, {0, std::nan("")}}, 8); }) ==
        "profile: point 2 is not finite");
}

// Arguments that gave an inside-out solid (negative length: negative signed
// volume), a mesh without triangles (radius 0, one ring), NaN vertices
// (cap_rings 0: 0/0) or named an argument the caller never passed ("profile"
// for make_sphere's radius) are refused, naming the caller's argument.
TEST_CASE("primitives: the solids refuse arguments that would give no solid, an inside-out one or NaN") {
  using iclap::test::what_of;
  CHECK(what_of([] { (void)iclap::make_cylinder(0.5, -1); }) == "length: must be finite and positive, got -1");
  CHECK(what_of([] { (void)iclap::make_cylinder(0, 1); }) == "radius: must be finite and positive, got 0");
  CHECK(what_of([] { (void)iclap::make_cylinder(-0.5, 1); }) == "radius: must be finite and positive, got -0.5");
  CHECK(what_of([] { (void)iclap::make_cylinder(0.5, 1, 2); }) == "segments: needs at least 3, got 2");
  CHECK(what_of([] { (void)iclap::make_frustum(0.3, 0.1, -1); }) == "length: must be finite and positive, got -1");
  CHECK(what_of([] { (void)iclap::make_frustum(0, 0, 1); }) == "r1: r0 and r1 are both 0: no solid");
  CHECK(what_of([] { (void)iclap::make_frustum(-0.1, 0.2, 1); }) == "r0: must be finite and >= 0, got -0.1");
  CHECK(what_of([] { (void)iclap::make_frustum(0, 0.2, 1); }) == "(no error)");  // a cone
  CHECK(what_of([] { (void)iclap::make_frustum(0.2, 0, 1); }) == "(no error)");
  CHECK(what_of([] { (void)iclap::make_capsule(0.2, -0.6); }) == "length: must be finite and positive, got -0.6");
  CHECK(what_of([] { (void)iclap::make_capsule(0.2, 0); }) == "length: must be finite and positive, got 0");
  CHECK(what_of([] { (void)iclap::make_capsule(0.2, 0.6, 24, 0); }) == "cap_rings: needs at least 1, got 0");
  CHECK(what_of([] { (void)iclap::make_capsule(0.2, 0.6, 24, 1); }) == "(no error)");
  CHECK(what_of([] { (void)iclap::make_sphere(1, 24, 1); }) == "rings: needs at least 2, got 1");
  CHECK(what_of([] { (void)iclap::make_sphere(0); }) == "radius: must be finite and positive, got 0");
  CHECK(what_of([] { (void)iclap::make_sphere(-1); }) == "radius: must be finite and positive, got -1");
  CHECK(what_of([] { (void)iclap::make_sphere(std::nan("")); }) == "radius: must be finite and positive, got nan");
  // At the smallest accepted settings each is still a closed, outward solid.
  for (const auto& m : {iclap::make_sphere(1, 3, 2), iclap::make_capsule(0.2, 0.6, 3, 1), iclap::make_frustum(0, 1, 1, 3)}) {
    CHECK(m.triangle_count() > 0);
    CHECK(m.vertices.allFinite());
    CHECK(iclap::signed_volume(m) > 0);
  }
}

TEST_CASE("primitives: extrusions of concave outlines are closed and outward, caps exactly cover the outline") {
  // A comb (three teeth), a notch whose tip touches the line between its
  // neighbours' neighbours, a square with a vertex in the middle of each
  // side and one starting at such a vertex (collinear points, which must not
  // be clipped as flat ears), a spike, and a star-shaped outline (found by a
  // search; integer corners, no three collinear) on which an ear test that
  // ignored the ear's edge a-b, rejecting ears for vertices beyond it, runs
  // out of ears: given either way round.
  const std::vector<std::vector<Eigen::Vector2d>> outlines = {
      {{0, 0}, {5, 0}, {5, 3}, {4, 3}, {4, 1}, {3, 1}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}},
      {{0, 0}, {1, -1}, {2, 0}, {2, 2}, {1.2, 2}, {1, 0}, {0.8, 2}, {0, 2}},
      {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}},
      {{1, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}},
      {{0, 0}, {4, 0}, {4, 4}, {3, 4}, {3, 1}, {2, 3}, {1, 1}, {1, 4}, {0, 4}},
      {{58, 23}, {69, 54}, {-61, -55}, {12, -17}, {57, -43}, {34, -22}, {21, -5}, {77, -13}, {86, -7}},
  };
  for (std::size_t o = 0; o < outlines.size(); ++o)
    for (bool reversed : {false, true}) {
      CAPTURE(o);
      CAPTURE(reversed);
      auto outline = outlines[o];
      if (reversed) std::reverse(outline.begin(), outline.end());
      const double area = std::abs(polygon_area(outline)), z0 = 0.25, z1 = 1.75;
      const auto prism = iclap::make_extrusion(outline, z0, z1);
      check_closed_outward(prism);
      CHECK(iclap::signed_volume(prism) == doctest::Approx(area * (z1 - z0)));
      // Overlapping or missing cap triangles would change the area.
      CHECK(iclap::surface_area(prism) == doctest::Approx(2 * area + perimeter(outline) * (z1 - z0)));
      CHECK(iclap::mesh_bounds(prism).min().z() == z0);
      CHECK(iclap::mesh_bounds(prism).max().z() == z1);
    }
}

TEST_CASE("primitives: make_extrusion refuses bad outlines and heights, naming the argument and why") {
  using V = std::vector<Eigen::Vector2d>;
  const V square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  CHECK(iclap::test::what_of([] { (void)iclap::make_extrusion(V{{0, 0}, {1, 0}}, 0, 1); }) ==
        "outline: needs at least 3 points");
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(square, 1, 1); }) == "z1: must be above z0");
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(square, 1, 0.5); }) == "z1: must be above z0");
  // Points on one line: the last edge runs back over the others.
  CHECK(iclap::test::what_of([] { (void)iclap::make_extrusion(V{{0, 0}, {1, 1}, {2, 2}, {3, 3}}, 0, 1); }) ==
        "outline: edges 2 and 3 fold back on each other: not a simple polygon");
  // A triangle so small that its doubled area underflows to 0 (1e-340), as
  // do the cross products that would find it degenerate.
  CHECK(iclap::test::what_of([] { (void)iclap::make_extrusion(V{{0, 0}, {1e-170, 0}, {0, 1e-170}}, 0, 1); }) ==
        "outline: has zero area");
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(square, 0, 1e-9); }) == "(no error)");
  // A bow-tie was extruded without complaint (its caps overlap); crossing
  // edges are named. Edges that only meet at a shared vertex are no crossing.
  CHECK(iclap::test::what_of([] { (void)iclap::make_extrusion(V{{0, 0}, {2, 2}, {2, 0}, {0, 1}}, 0, 1); }) ==
        "outline: edges 0 and 2 cross: not a simple polygon");
  V pentagram;  // every second corner of a regular pentagon: each edge crosses the two not next to it
  for (int k = 0; k < 5; ++k) pentagram.emplace_back(std::cos(kPi / 2 + k * 4 * kPi / 5), std::sin(kPi / 2 + k * 4 * kPi / 5));
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(pentagram, 0, 1); }) ==
        "outline: edges 0 and 2 cross: not a simple polygon");
  // Outlines that touch themselves without crossing were extruded too:
  // repeated points (in a row, through the closing edge, or apart), a spike
  // of zero width, a point on an edge not its own. Each gave degenerate
  // walls or caps that share a point or an edge; each is named.
  auto outline_error = [](const V& outline) {
    return iclap::test::what_of([&] { (void)iclap::make_extrusion(outline, 0, 1); });
  };
  CHECK(outline_error({{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}}) ==
        "outline: points 1 and 2 coincide: not a simple polygon");
  CHECK(outline_error({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}}) ==
        "outline: points 0 and 4 coincide: not a simple polygon");
  CHECK(outline_error({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}) ==
        "outline: points 2 and 5 coincide: not a simple polygon");
  CHECK(outline_error({{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 1}, {1, 1.5}, {0, 2}}) ==
        "outline: edges 3 and 4 fold back on each other: not a simple polygon");
  CHECK(outline_error({{0, 0}, {4, 0}, {4, 2}, {2, 0}, {0, 2}}) ==
        "outline: point 3 lies on edge 0: not a simple polygon");
  // Two rectangles joined along x = 2, 0 <= y <= 1, where edges 1 and 5
  // overlap: found as the first point of one on the other, point 1 (2, 0)
  // on edge 5 (from (2, -1) to (2, 1)).
  CHECK(outline_error({{0, 0}, {2, 0}, {2, 2}, {4, 2}, {4, -1}, {2, -1}, {2, 1}, {0, 1}}) ==
        "outline: point 1 lies on edge 5: not a simple polygon");
  // Each again given the other way round is still refused.
  for (const V& bad : {V{{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}},
                       V{{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 1}, {1, 1.5}, {0, 2}},
                       V{{0, 0}, {4, 0}, {4, 2}, {2, 0}, {0, 2}}}) {
    V reversed(bad.rbegin(), bad.rend());
    CHECK(outline_error(reversed).find("not a simple polygon") != std::string::npos);
  }
  // Collinear points going on in the same direction, and a point near an
  // edge but not on it, are a simple polygon.
  CHECK(outline_error({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}}) == "(no error)");
  CHECK(outline_error({{0, 0}, {4, 0}, {4, 2}, {2, 1e-9}, {0, 2}}) == "(no error)");
  // A NaN point gave a NaN mesh; an infinite height, infinite vertices.
  CHECK(iclap::test::what_of([] { (void)iclap::make_extrusion(V{{0, 0}, {1, 0}, {std::nan(""), 1}}, 0, 1); }) ==
        "outline: point 2 is not finite");
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(square, -HUGE_VAL, 1); }) ==
        "z0: must be finite, got -inf");
  CHECK(iclap::test::what_of([&] { (void)iclap::make_extrusion(square, 0, HUGE_VAL); }) == "z1: must be finite, got inf");
}

TEST_CASE("primitives: arc_points runs from `from` to `to` in equal steps, both ends included") {
  const Eigen::Vector2d centre(1, -2);
  const double r = 0.5, from = kPi / 2, to = 5 * kPi / 4;
  const auto p = iclap::arc_points(centre, r, from, to, 6);
  REQUIRE(p.size() == 7);
  CHECK((p.front() - (centre + r * Eigen::Vector2d(0, 1))).norm() < 1e-12);
  CHECK((p.back() - (centre + r * Eigen::Vector2d(-std::sqrt(0.5), -std::sqrt(0.5)))).norm() < 1e-12);
  const double step = 2 * r * std::sin((to - from) / 6 / 2);  // chord of one step
  for (std::size_t i = 0; i < p.size(); ++i) {
    CHECK((p[i] - centre).norm() == doctest::Approx(r));
    if (i > 0) {
      CHECK((p[i] - p[i - 1]).norm() == doctest::Approx(step));
      // Counter-clockwise when to > from.
      CHECK((p[i - 1] - centre).x() * (p[i] - centre).y() - (p[i - 1] - centre).y() * (p[i] - centre).x() > 0);
    }
  }
}

TEST_CASE("primitives: arc_points refuses what would give NaN or no arc, naming the argument") {
  using iclap::test::what_of;
  const Eigen::Vector2d c(0, 0);
  // steps 0 divided 0 by 0: one NaN point.
  CHECK(what_of([&] { (void)iclap::arc_points(c, 1, 0, 1, 0); }) == "steps: needs at least 1, got 0");
  CHECK(what_of([&] { (void)iclap::arc_points(c, 1, 0, 1, 1); }) == "(no error)");
  CHECK(iclap::arc_points(c, 1, 0, 1, 1).size() == 2);
  CHECK(what_of([&] { (void)iclap::arc_points(c, 0, 0, 1, 4); }) == "radius: must be finite and positive, got 0");
  CHECK(what_of([&] { (void)iclap::arc_points(c, 1, std::nan(""), 1, 4); }) == "from: must be finite, got nan");
  CHECK(what_of([&] { (void)iclap::arc_points(c, 1, 0, HUGE_VAL, 4); }) == "to: must be finite, got inf");
  CHECK(what_of([] { (void)iclap::arc_points({std::nan(""), 0}, 1, 0, 1, 4); }) == "centre: is not finite");
}
