// SPDX-License-Identifier: MIT
// sample_surface: every sample on the mesh (BVH closest point), every
// surface point within `spacing` of a sample (brute force over random
// surface points, slivers and degenerate triangles included), counts that
// follow the area, determinism, and errors that name their argument.

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/mesh/mesh.hpp"
#include "../support/zero_area_mesh.hpp"

namespace {

using iclap::Index;

/// A point uniform on the surface: a triangle drawn by area, then a uniform
/// point of it.
Eigen::Vector3d random_surface_point(const iclap::TriangleMesh& m, const std::vector<double>& cdf, iclap::Rng& rng) {
  const double u = rng.uniform() * cdf.back();
  Index t = 0;
  while (t + 1 < static_cast<Index>(cdf.size()) && cdf[static_cast<std::size_t>(t)] <= u) ++t;
  double r1 = rng.uniform(), r2 = rng.uniform();
  if (r1 + r2 > 1) {
    r1 = 1 - r1;
    r2 = 1 - r2;
  }
  const Eigen::Vector3d a = m.corner(t, 0);
  return a + r1 * (m.corner(t, 1) - a) + r2 * (m.corner(t, 2) - a);
}

std::vector<double> area_cdf(const iclap::TriangleMesh& m) {
  std::vector<double> cdf;
  double total = 0;
  for (Index t = 0; t < m.triangle_count(); ++t) cdf.push_back(total += m.area_normal(t).norm());
  return cdf;
}

/// Largest distance from `queries` random surface points (and every
/// triangle's corners and centroid) to their closest sample, by brute force.
double coverage_radius(const iclap::TriangleMesh& m, const Eigen::Matrix3Xd& samples, int queries, std::uint64_t seed) {
  iclap::Rng rng(seed);
  const auto cdf = area_cdf(m);
  std::vector<Eigen::Vector3d> q;
  for (int i = 0; i < queries; ++i) q.push_back(random_surface_point(m, cdf, rng));
  for (Index t = 0; t < m.triangle_count(); ++t) {
    q.push_back((m.corner(t, 0) + m.corner(t, 1) + m.corner(t, 2)) / 3);
    for (int k = 0; k < 3; ++k) q.push_back(m.corner(t, k));
  }
  double worst = 0;
  for (const auto& p : q) worst = std::max(worst, std::sqrt((samples.colwise() - p).colwise().squaredNorm().minCoeff()));
  return worst;
}

/// Largest distance from a sample to the mesh (BVH closest point).
double off_surface(const iclap::TriangleMesh& m, const Eigen::Matrix3Xd& samples) {
  const iclap::MeshBvh bvh(m);
  double worst = 0;
  for (Index i = 0; i < samples.cols(); ++i)
    worst = std::max(worst, std::sqrt(bvh.closest_point(samples.col(i)).squared_distance));
  return worst;
}

iclap::TriangleMesh make_mesh(const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3i>& t) {
  iclap::TriangleMesh m;
  m.vertices.resize(3, static_cast<Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) m.vertices.col(static_cast<Index>(i)) = v[i];
  m.triangles.resize(3, static_cast<Index>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) m.triangles.col(static_cast<Index>(i)) = t[i];
  return m;
}

/// A single triangle.
iclap::TriangleMesh triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return make_mesh({a, b, c}, {Eigen::Vector3i(0, 1, 2)});
}

}  // namespace

TEST_CASE("sample_surface: samples lie on the mesh and cover it within spacing") {
  struct Case {
    std::string name;
    iclap::TriangleMesh mesh;
    double spacing;
  };
  // Slivers: a long thin cylinder (CAD-like fans of 60 mm x 0.6 mm
  // triangles), a box, a bumpy sphere, a far-away obtuse triangle, and a
  // mesh with degenerate triangles beside a proper one.
  iclap::TriangleMesh bumpy = iclap::make_sphere(0.03, 40, 20);
  iclap::Rng rng(7);
  for (Index v = 0; v < bumpy.vertex_count(); ++v) bumpy.vertices.col(v) *= 1.0 + 0.1 * rng.uniform();
  iclap::TriangleMesh degenerate = triangle({0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0});
  iclap::append_mesh(degenerate, triangle({0, 0, 0.01}, {0.02, 0, 0.01}, {0.01, 0, 0.01}));  // collinear
  iclap::append_mesh(degenerate, triangle({0, 0, 0.02}, {0, 0, 0.02}, {0, 0, 0.02}));        // a point
  const std::vector<Case> cases = {
      {"thin cylinder", iclap::make_cylinder(0.006, 0.06, 64), 0.5e-3},
      {"box", iclap::make_box({0.05, 0.02, 0.01}), 1e-3},
      {"bumpy sphere", bumpy, 0.7e-3},
      {"obtuse triangle at 1e3 m", triangle({1000, 1000, 1000}, {1000.05, 1000, 1000}, {1000.01, 1000.002, 1000}), 0.3e-3},
      {"degenerate triangles", degenerate, 0.4e-3},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    const Eigen::Matrix3Xd s = iclap::sample_surface(c.mesh, c.spacing);
    REQUIRE(s.cols() > 0);
    REQUIRE(s.allFinite());
    const double scale = std::max(1.0, c.mesh.vertices.cwiseAbs().maxCoeff());
    CHECK(off_surface(c.mesh, s) <= 1e-12 * scale);
    const double r = coverage_radius(c.mesh, s, 2000, 11);
    CHECK(r <= c.spacing * (1 + 1e-9) + 1e-12 * scale);
    // The bound is not slack: the farthest surface points are more than
    // half a spacing from every sample.
    if (c.name != "degenerate triangles") CHECK(r > 0.3 * c.spacing);
    // Every corner of every triangle is a sample.
    for (Index t = 0; t < c.mesh.triangle_count(); ++t)
      for (int k = 0; k < 3; ++k) CHECK((s.colwise() - c.mesh.corner(t, k)).colwise().squaredNorm().minCoeff() == 0.0);
  }
}

TEST_CASE("sample_surface: the count follows the area, not the triangles' shapes") {
  const double spacing = 1e-3;
  // One square of 40 x 40 mm as 2 triangles and as 800 slivers of 40 x
  // 0.1 mm: about 1.15 area / spacing^2 points either way, plus the edges.
  const double side = 0.04;
  iclap::TriangleMesh coarse = make_mesh({{0, 0, 0}, {side, 0, 0}, {side, side, 0}, {0, side, 0}},
                                                {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)});
  iclap::TriangleMesh slivers;
  const int strips = 400;
  {
    std::vector<Eigen::Vector3d> v;
    std::vector<Eigen::Vector3i> t;
    for (int i = 0; i <= strips; ++i) {
      v.emplace_back(0, side * i / strips, 0);
      v.emplace_back(side, side * i / strips, 0);
    }
    for (int i = 0; i < strips; ++i) {
      t.emplace_back(2 * i, 2 * i + 1, 2 * i + 3);
      t.emplace_back(2 * i, 2 * i + 3, 2 * i + 2);
    }
    slivers = make_mesh(v, t);
  }
  const double ideal = 1.1547 * side * side / (spacing * spacing);  // 1848
  const auto n_coarse = static_cast<double>(iclap::sample_surface(coarse, spacing).cols());
  const auto n_slivers = static_cast<double>(iclap::sample_surface(slivers, spacing).cols());
  CHECK(n_coarse >= ideal);
  CHECK(n_coarse <= 1.3 * ideal);
  // Each sliver (its height 0.1 mm) is one row of 42 points along its
  // 40 mm diagonal and its apex: about 800 x 43 points, 19 times the ideal
  // count (a sliver narrower than the spacing costs its length), but not the
  // 41 x 42 / 2 = 861 points per triangle of a lattice that followed the
  // longest edge in both directions.
  CHECK(n_slivers == 2 * strips * 43);
  CHECK(n_slivers >= ideal);

  // Scaling the mesh by 2 (the area by 4) multiplies the count by about 4;
  // halving the spacing does the same.
  iclap::TriangleMesh box = iclap::make_box({0.05, 0.03, 0.02});
  const auto n1 = static_cast<double>(iclap::sample_surface(box, 1e-3).cols());
  iclap::TriangleMesh big = box;
  big.vertices *= 2;
  const auto n2 = static_cast<double>(iclap::sample_surface(big, 1e-3).cols());
  const auto n_half = static_cast<double>(iclap::sample_surface(box, 0.5e-3).cols());
  CHECK(n2 / n1 == doctest::Approx(4).epsilon(0.05));
  CHECK(n_half / n1 == doctest::Approx(4).epsilon(0.05));
  const double area = iclap::surface_area(box);
  CHECK(n1 >= 1.1547 * area / 1e-6);
  CHECK(n1 <= 1.3 * 1.1547 * area / 1e-6);
}

TEST_CASE("sample_surface: deterministic") {
  const iclap::TriangleMesh m = iclap::make_capsule(0.01, 0.05);
  const Eigen::Matrix3Xd a = iclap::sample_surface(m, 0.8e-3), b = iclap::sample_surface(m, 0.8e-3);
  REQUIRE(a.cols() == b.cols());
  CHECK((a - b).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("sample_surface: errors name the argument") {
  const iclap::TriangleMesh box = iclap::make_box({0.05, 0.03, 0.02});
  for (const double bad : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    CAPTURE(bad);
    CHECK_THROWS_WITH_AS(iclap::sample_surface(box, bad), doctest::Contains("spacing: must be finite and positive"),
                         iclap::InvalidArgument);
  }
  // Too fine for the mesh: refused with the number of points it would take.
  // 1 um on a 62 cm^2 box: about 7e9 points, refused by the quick bound
  // without walking its rows.
  try {
    (void)iclap::sample_surface(box, 1e-6);
    FAIL("no exception");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "spacing");
    CHECK(std::string(e.what()).find("would take at least ") != std::string::npos);
    CHECK(std::string(e.what()).find("e+09 points") != std::string::npos);
    CHECK(std::string(e.what()).find("more than the 5e+07 allowed") != std::string::npos);
  }
  // Over the bound but not far: the exact count. A 1 m square at 0.14 mm
  // takes about 1.15 / 0.14e-3^2 = 5.9e7 points.
  const iclap::TriangleMesh square = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},
                                                      {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)});
  try {
    (void)iclap::sample_surface(square, 0.14e-3);
    FAIL("no exception");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "spacing");
    CAPTURE(std::string(e.what()));  // 5.89498e+07 points
    CHECK(std::string(e.what()).find("spacing: 0.00014 would take 5.89") != std::string::npos);
    CHECK(std::string(e.what()).find("at least") == std::string::npos);
  }
  // The mesh is validated, naming "mesh".
  CHECK_THROWS_WITH_AS(iclap::sample_surface(iclap::test::zero_area_mesh(), 1e-3), doctest::Contains("mesh: every one"),
                       iclap::InvalidArgument);
  CHECK_THROWS_WITH_AS(iclap::sample_surface(iclap::TriangleMesh{}, 1e-3), doctest::Contains("mesh: has no triangles"),
                       iclap::EmptyInput);
  iclap::TriangleMesh nan = box;
  nan.vertices(1, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(iclap::sample_surface(nan, 1e-3), doctest::Contains("mesh: vertex 3 is not finite"),
                       iclap::InvalidArgument);
}

// --- Reproducer of a defect found by helper-40's audit (session 49), fixed in the same
// session. "Happens" is what the library did before the fix.

TEST_CASE("sampling: a valid mesh with huge coordinates is sampled like its scaled-down copy") {
  // A right triangle of legs 1 at spacing 0.1 takes 85 points; scaling the
  // triangle and the spacing by the same power of ten should not change
  // that (validate_mesh accepts these meshes). Expected: 85 points, or, if
  // such coordinates are out of scope, a refusal that says so (as
  // place_on_table's "has a coordinate of magnitude ..., more than 1e+75").
  // Happens: the triangle's area and height overflow, and the refusal
  // claims "spacing: 1e+99 would take at least inf points on this mesh
  // (surface area inf)" at 1e100 and "... at least -nan points ..." at
  // 1e160 and beyond.
  for (const double s : {1.0, 1e100, 1e160, 1e300}) {
    CAPTURE(s);
    iclap::TriangleMesh m;
    m.vertices.resize(3, 3);
    m.vertices << 0, s, 0, 0, 0, s, 0, 0, 0;
    m.triangles.resize(3, 1);
    m.triangles << 0, 1, 2;
    std::string outcome;
    try {
      outcome = std::to_string(iclap::sample_surface(m, s / 10).cols()) + " points";
    } catch (const iclap::InvalidArgument& e) {
      outcome = e.what();
    }
    CHECK(outcome.find("nan") == std::string::npos);
    CHECK(outcome.find("inf points") == std::string::npos);
    CHECK((outcome == "85 points" || outcome.find("coordinate") != std::string::npos));
  }
}
