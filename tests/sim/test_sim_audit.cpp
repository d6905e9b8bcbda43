// SPDX-License-Identifier: MIT
// Reproducers from helper-54a's audit (session 54) of the simulator
// (include/iclap/sim) and the mesh geometry (include/iclap/mesh, not the
// loaders). Each case failed on the code it was written against and was
// fixed in the same session; it states the behaviour the contract (doc
// comment) promises, and its comment says what happened before ("Now").

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iclap/mesh/mesh.hpp"
#include "iclap/mesh/primitives.hpp"
#include "iclap/sim/sim.hpp"
#include "../support/errors.hpp"

namespace {

iclap::TriangleMesh triangles_of(const std::vector<Eigen::Vector3d>& corners) {
  iclap::TriangleMesh m;
  m.vertices.resize(3, static_cast<iclap::Index>(corners.size()));
  for (std::size_t i = 0; i < corners.size(); ++i) m.vertices.col(static_cast<iclap::Index>(i)) = corners[i];
  m.triangles.resize(3, static_cast<iclap::Index>(corners.size() / 3));
  for (iclap::Index t = 0; t < m.triangles.cols(); ++t)
    m.triangles.col(t) << static_cast<int>(3 * t), static_cast<int>(3 * t + 1), static_cast<int>(3 * t + 2);
  return m;
}

}  // namespace

// Input: MeshBvh over two triangles: triangle 0 has corners 0 and 1 equal,
// (0,0,0), (0,0,0), (1,0,0) (a zero-area triangle along the segment to
// (1,0,0), as STL/CAD exports often hold and validate_mesh accepts because
// triangle 1 has area); triangle 1 is a proper triangle at z = 5. Query
// p = (0.5, 0.1, 0).
// Now: closest_on_triangle(p, a, a, c) returns (nan, nan, nan): with a == b,
// d1 = d3 = 0, vc = 0, and the edge-ab branch divides 0 / 0. The NaN distance
// never wins the comparison, so closest_point silently answers triangle 1,
// point (0.5, 0.1, 5), squared distance 25, while the true answer is
// (0.5, 0, 0) on triangle 0 at squared distance 0.01 (brute force over the
// segment).
// Should: "The surface point closest to p": triangle 0, (0.5, 0, 0), 0.01;
// closest_on_triangle never returns NaN for finite input.
// Cause: include/iclap/mesh/bvh.hpp:184 (a + (d1 / (d1 - d3)) * ab with
// d1 = d3 = 0 when corner 0 == corner 1).
TEST_CASE("bvh audit: closest_point on a triangle whose first two corners coincide") {
  const Eigen::Vector3d p(0.5, 0.1, 0);
  const Eigen::Vector3d q = iclap::MeshBvh::closest_on_triangle(p, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                                 Eigen::Vector3d(1, 0, 0));
  CHECK(q.allFinite());
  CHECK(q.isApprox(Eigen::Vector3d(0.5, 0, 0)));
  const iclap::MeshBvh bvh(triangles_of({{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 0, 5}, {1, 0, 5}, {0, 1, 5}}));
  const iclap::ClosestPoint c = bvh.closest_point(p);
  CHECK(c.triangle == 0);
  CHECK(c.squared_distance == doctest::Approx(0.01));
  CHECK(c.point.isApprox(Eigen::Vector3d(0.5, 0, 0)));
}

// Input: TactileSensorSettings with spread_sigma = 1e-200 m (any positive
// value below about 2.5e-165 m: "practically no spread"), which validate()
// accepts (finite and >= 0); the pad pressed onto a flat plate.
// Now: every reading is NaN (render(...)(0, 0) == -nan), in every frame of
// simulate_exploration too (57 of 57 frames have NaN pressures; the same
// with an absurdly large pitch, where spread_sigma / sample underflows the
// same way). The kernel's sig * sig underflows to 0, so its centre weight is
// exp(-0.5 * 0 / 0) = NaN, and NaN passes the dead band and the saturation
// (std::min(NaN, max_raw) is NaN).
// Should: either refused naming "sensor.spread_sigma", or (better) read
// like spread_sigma = 0: finite readings, the same as with no spread.
// Cause: include/iclap/sim/sensor.hpp:135-136 (kernel weight with sig > 0
// but sig * sig == 0).
TEST_CASE("sensor audit: a tiny positive spread_sigma that validate() accepts gives NaN readings") {
  iclap::TactileSensorSettings s;
  s.noise_sigma = 0;
  s.dead_band = 0;
  const iclap::MeshBvh plate(iclap::transformed(iclap::make_box({0.2, 0.1, 0.02}),
                                                Eigen::Affine3d(Eigen::Translation3d(0, 0, 0.01))));
  iclap::PadPose pose;
  pose.centre = Eigen::Vector3d(0, 0, 0.02);
  pose.axes.col(0) = Eigen::Vector3d::UnitX();
  pose.axes.col(2) = -Eigen::Vector3d::UnitZ();
  pose.axes.col(1) = pose.axes.col(2).cross(pose.axes.col(0));
  auto reading = [&](const iclap::TactileSensorSettings& settings) {
    const iclap::TactileSensorModel model(settings);
    iclap::PadContact contact;
    model.probe(plate, pose, contact);
    return model.render(contact, model.balance(contact, 3.0), nullptr);
  };
  s.spread_sigma = 0;
  const Eigen::MatrixXd sharp = reading(s);
  s.spread_sigma = 1e-200;
  const std::string refused = iclap::test::argument_of([&] { s.validate(); });
  if (refused == "(no error)") {
    const Eigen::MatrixXd tiny = reading(s);
    CHECK(tiny.allFinite());
    CHECK(tiny.isApprox(sharp));
  } else {
    CHECK(refused == "sensor.spread_sigma");
  }
}

// Input: SimulationSettings with exploration.frame_rate = 1e-310 (a
// subnormal, finite and > 0, so ExplorationSettings::validate accepts it),
// simulate_exploration of the built-in wooden_cuboid_1.
// Now: every frame after the first has t = inf (k / 1e-310 overflows), and
// positions are inf for some frames (dt = 1 / 1e-310 = inf). The same
// defect ArmSettings::validate fixed for a subnormal position_resolution
// ("a subnormal one made every position infinite").
// Should: refused with InvalidArgument naming "exploration.frame_rate" (e.g.
// a lower bound such that 1 / frame_rate and max frames / frame_rate stay
// finite), or finite times and positions.
// Cause: include/iclap/sim/exploration.hpp:105 (check_positive only), used
// at :176 (dt_ = 1.0 / frame_rate) and :551 (t = k / frame_rate).
TEST_CASE("simulator audit: a subnormal frame_rate is accepted and gives infinite times and positions") {
  iclap::SimulationSettings s;
  s.exploration.max_frames_mean = 20;
  s.exploration.frame_rate = 1e-310;
  const std::string refused = iclap::test::argument_of([&] { s.validate(); });
  if (refused == "(no error)") {
    const auto frames = iclap::simulate_exploration(iclap::builtin_object("wooden_cuboid_1"), s, 7, 0);
    for (const auto& f : frames) {
      CAPTURE(f.frame);
      CHECK(std::isfinite(*f.time));
      CHECK(f.position.allFinite());
    }
  } else {
    CHECK(refused == "exploration.frame_rate");
  }
}

// Input: make_lathe({{0, 1}, {1, 1}, {1, 0}, {0, 0}}, 8): a closed cylinder
// profile listed from the top to the bottom instead of bottom to top.
// Now: returns an inside-out solid without complaint: signed_volume = -2.83
// (the cylinder's polygon volume, negated).
// Should: primitives.hpp's header promises "Arguments that would give no
// solid, an inside-out one or a non-finite vertex are refused with an
// InvalidArgument naming the argument": refused naming "profile" (or the
// profile made outward, i.e. reversed, if top-to-bottom is to be allowed).
// Cause: include/iclap/mesh/primitives.hpp:71-107 (make_lathe checks each
// point but not the orientation of the profile).
TEST_CASE("primitives audit: make_lathe with a top-to-bottom profile gives an inside-out solid silently") {
  const std::vector<Eigen::Vector2d> downwards = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  std::string refused;
  double volume = 0;
  try {
    volume = iclap::signed_volume(iclap::make_lathe(downwards, 8));
    refused = "(no error)";
  } catch (const iclap::InvalidArgument& e) {
    refused = e.argument();
  }
  if (refused == "(no error)") CHECK(volume > 0);
  else CHECK(refused == "profile");
}

// Input: make_lathe({{0, 0}, {0, 1}}, 8): a profile of two poles (an axis
// segment only).
// Now: returns a TriangleMesh with 0 triangles (and 2 vertices), no error;
// it only fails later, in whatever takes it (validate_mesh: "has no
// triangles", under that caller's argument name).
// Should: the header's promise ("Arguments that would give no solid ... are
// refused with an InvalidArgument naming the argument"): refused naming
// "profile".
// Cause: include/iclap/mesh/primitives.hpp:88-107 (the loop skips segments
// between two poles; nothing checks that any triangle came out).
TEST_CASE("primitives audit: make_lathe with a profile of poles only returns a mesh without triangles") {
  CHECK(iclap::test::argument_of([] { (void)iclap::make_lathe({{0, 0}, {0, 1}}, 8); }) == "profile");
}

// Input: make_capsule(1e308, 1.7e308) (finite, positive radius and length).
// Now: throws InvalidArgument "profile: point 0 is not finite": the capsule
// end -length/2 - radius overflows to -inf and make_lathe's check fires,
// naming "profile", an argument make_capsule's caller never passed (the
// class of defect test_primitives.cpp's "refuse ... naming the caller's
// argument" case fixed for make_sphere's radius).
// Should: InvalidArgument naming the caller's argument ("length" or
// "radius", e.g. "total length length + 2 radius overflows").
// Cause: include/iclap/mesh/primitives.hpp:135-151 (make_capsule builds the
// profile without checking that h + radius is finite; make_lathe at :78
// names "profile").
TEST_CASE("primitives audit: make_capsule whose total length overflows names 'profile', not its argument") {
  const std::string named = iclap::test::argument_of([] { (void)iclap::make_capsule(1e308, 1.7e308); });
  CHECK(named != "(no error)");
  CHECK((named == "length" || named == "radius"));
}

// Input: a single triangle (0,0,0), (k,0,0), (0,k,0) with k = 1e-78 (and
// 1e-100): validate_mesh and check_mesh_range accept it (only coordinates
// beyond 1e75 are refused), MeshBvh builds. Query p = (0.25, 0.25, 1) k,
// right above an interior point.
// Now: k = 1e-78: closest_point answers triangle -1, squared distance inf
// (the "no triangle found" answer test_mesh_geometry.cpp fixed for huge
// coordinates); k = 1e-100: triangle 0 but point (0.25 k, 0, 0) on an edge,
// squared distance 1.0625 k^2 instead of k^2. The barycentric terms
// va, vb, vc are products of two dot products (~k^4) and underflow to 0
// (or to subnormals, whose 1 / (va + vb + vc) overflows): vc == 0 sends
// every interior query to edge ab, and 0 * inf gives NaN.
// Should: "The surface point closest to p": triangle 0, (0.25, 0.25, 0) k,
// squared distance k^2 (as at k = 1e-75), or a refusal naming "mesh" of
// coordinates too small, like the 1e75 bound on the large side.
// Cause: include/iclap/mesh/bvh.hpp:183-193 (closest_on_triangle's
// unscaled products); MeshBvh's constructor (bvh.hpp:60-62) checks only the
// large side of the range.
TEST_CASE("bvh audit: closest_point on a mesh with tiny coordinates finds no triangle or a wrong point") {
  for (const double k : {1e-78, 1e-100}) {
    CAPTURE(k);
    iclap::TriangleMesh m = triangles_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    m.vertices *= k;
    std::string refused = "(no error)";
    try {
      const iclap::MeshBvh bvh(m);
      const iclap::ClosestPoint c = bvh.closest_point(Eigen::Vector3d(0.25, 0.25, 1) * k);
      CHECK(c.triangle == 0);
      CHECK((c.point / k).isApprox(Eigen::Vector3d(0.25, 0.25, 0)));
      CHECK(c.squared_distance / (k * k) == doctest::Approx(1.0));
    } catch (const iclap::InvalidArgument& e) {
      refused = e.argument();
    }
    if (refused != "(no error)") CHECK(refused == "mesh");
  }
}

// Input: sample_surface of the single triangle (0,0,0), (k,0,0), (0,k,0)
// with k = 1e-100 (accepted by validate_mesh and check_mesh_range) at
// spacing 0.1 k.
// Now: 16 points, all on the hypotenuse: corner (0,0,0) is 7.07 spacings
// from the nearest sample (at k = 1: 85 points, the worst point of the
// triangle 0.56 spacing away). The row count uses height =
// |(b - a) x (c - a)| / |b - a|, and Eigen's norm() squares the cross
// product's components (~k^2, squared ~k^4 = 1e-400): it underflows to 0,
// so the triangle gets no rows beyond its longest edge.
// Should: as documented, "every point of every triangle lies within
// `spacing` ... of one of them" (the same points as the scaled-up copy,
// scaled), or a refusal naming "mesh".
// Cause: include/iclap/mesh/sampling.hpp:53 (cross(...).norm() underflows;
// stableNorm(), or dividing b - a by its length first, would not).
TEST_CASE("sampling audit: a mesh with tiny coordinates is sampled only along its longest edges") {
  const double k = 1e-100, spacing = 0.1 * k;
  iclap::TriangleMesh m = triangles_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  m.vertices *= k;
  std::string refused = "(no error)";
  try {
    const Eigen::Matrix3Xd points = iclap::sample_surface(m, spacing);
    double worst = 0;  // over a grid of the triangle's points, in units of spacing
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; i + j <= 20; ++j) {
        const Eigen::Vector3d q(i / 20.0, j / 20.0, 0);
        double nearest = 1e300;
        for (iclap::Index c = 0; c < points.cols(); ++c)
          nearest = std::min(nearest, (points.col(c) / k - q).norm() * k / spacing);
        worst = std::max(worst, nearest);
      }
    CHECK(worst <= 1.0);
  } catch (const iclap::InvalidArgument& e) {
    refused = e.argument();
  }
  if (refused != "(no error)") CHECK(refused == "mesh");
}
