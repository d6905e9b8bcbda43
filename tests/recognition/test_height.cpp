// SPDX-License-Identifier: MIT
// Pad normals of touches and the registration-free height classifier.
#include <doctest/doctest.h>

#include <cmath>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/tactile/raw_pressures.hpp"

using namespace iclap;

namespace {

constexpr double kPi = 3.141592653589793;

/// A unit normal tilted by `tilt` from straight down, leaning towards `azimuth`.
Eigen::Vector3d normal(double tilt, double azimuth) {
  return {std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth), -std::cos(tilt)};
}

TouchSet touches(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& normals) {
  TouchSet s;
  s.positions.resize(3, static_cast<Index>(positions.size()));
  s.normals.resize(3, static_cast<Index>(normals.size()));
  for (std::size_t i = 0; i < positions.size(); ++i) s.positions.col(static_cast<Index>(i)) = positions[i];
  for (std::size_t i = 0; i < normals.size(); ++i) s.normals.col(static_cast<Index>(i)) = normals[i];
  return s;
}

}  // namespace

TEST_CASE("height_and_tilt: height and tilt from straight down") {
  const Eigen::Vector3d p(0.3, -0.2, 0.025);
  CHECK(height_and_tilt(p, normal(0, 0)) == Eigen::Vector2d(0.025, 0.0));
  CHECK(height_and_tilt(p, Eigen::Vector3d(0, -1, 0))(1) == doctest::Approx(kPi / 2));
  CHECK(height_and_tilt(p, Eigen::Vector3d(0, 0, 1))(1) == doctest::Approx(kPi));  // pressing upwards
  CHECK(height_and_tilt(p, normal(0.4, 2.0))(1) == doctest::Approx(0.4).epsilon(1e-12));
  // Tiny tilts keep their precision (atan2, not acos of a rounded cosine).
  CHECK(height_and_tilt(p, normal(1e-9, 0.3))(1) == doctest::Approx(1e-9).epsilon(1e-6));
}

TEST_CASE("touch tables carry the pad normals when every contact frame has an orientation") {
  Dataset ds;
  ds.rows = 14;
  ds.cols = 6;
  Frame f;
  f.object = "a";
  f.position = Eigen::Vector3d(0, 0, 0.01);
  f.pressures = Eigen::MatrixXd::Constant(14, 6, 100);
  // Pad x along world x, pad z (into the object) turned from world -z towards +x by 30 degrees.
  f.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi - kPi / 6, Eigen::Vector3d::UnitY()));
  Frame g = f;
  g.frame = 1;
  g.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()));  // straight down
  Frame idle = f;
  idle.frame = 2;
  idle.pressures.setZero();
  idle.orientation.reset();  // not a touch: its missing orientation does not matter
  ds.frames = {f, g, idle};
  const TouchTable t = make_touch_table(ds, RawPressures<float>{}, 20.0);
  REQUIRE(t.size() == 2);
  REQUIRE(t.touches.has_normals());
  CHECK((t.touches.normals.col(0) - Eigen::Vector3d(0.5, 0, -std::sqrt(3.0) / 2)).norm() < 1e-12);
  CHECK((t.touches.normals.col(1) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-12);
  CHECK(height_and_tilt(t.touches.positions.col(0), t.touches.normals.col(0))(1) == doctest::Approx(kPi / 6));
  const TouchSet second = select_touches(t.touches, std::vector<Index>{1});
  CHECK(second.normals.col(0) == t.touches.normals.col(1));
  CHECK_NOTHROW(second.validate("s"));
  // One touch without an orientation: no normals at all, rather than a guess.
  ds.frames[1].orientation.reset();
  CHECK(!make_touch_table(ds, RawPressures<float>{}, 20.0).touches.has_normals());
}

TEST_CASE("touch sets reject normals of the wrong count, non-finite or not of unit length") {
  TouchSet s = touches({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, {normal(0, 0), normal(1, 0)});
  CHECK_NOTHROW(s.validate("s"));
  TouchSet fewer = s;
  fewer.normals.conservativeResize(3, 1);
  CHECK_THROWS_AS(fewer.validate("s"), DimensionMismatch);
  TouchSet nan = s;
  nan.normals(2, 1) = std::nan("");
  CHECK_THROWS_AS(nan.validate("s"), NonFiniteValue);
  TouchSet longer = s;
  longer.normals.col(1) *= 2.0;
  CHECK_THROWS_WITH_AS(longer.validate("s"), "s.normals: column 1 is not a unit vector (norm 2.000000)",
                       InvalidArgument);
}

TEST_CASE("height distance: the closest training touch in (z, s theta), summed over the test") {
  // Object 0 touched on top at 10 mm, object 1 on top at 30 mm and on a
  // vertical side at 15 mm.
  const TouchSet a = touches({{0.0, 0.0, 0.010}, {0.05, 0.0, 0.010}}, {normal(0, 0), normal(0, 1)});
  const TouchSet b = touches({{0.0, 0.0, 0.030}, {0.1, 0.0, 0.015}}, {normal(0, 0), normal(kPi / 2, 0)});
  HeightClassifier height;
  height.tilt_scale = 0.02;
  height.fit({a, b}, 0);
  REQUIRE(height.objects() == 2);
  // A touch at 12 mm tilted by 0.1 rad, and a vertical side at 16 mm.
  const TouchSet test = touches({{0.3, 0.4, 0.012}, {-0.2, 0.1, 0.016}}, {normal(0.1, 0.5), normal(kPi / 2, 2.0)});
  Eigen::VectorXd d(2);
  height.distances(test, d);
  const double s = 0.02;
  const double to_a = (0.002 * 0.002 + s * s * 0.1 * 0.1) + (0.006 * 0.006 + s * s * (kPi / 2) * (kPi / 2));
  const double first_to_b = std::min(0.018 * 0.018 + s * s * 0.1 * 0.1, 0.003 * 0.003 + s * s * (kPi / 2 - 0.1) * (kPi / 2 - 0.1));
  const double to_b = first_to_b + 0.001 * 0.001;
  CHECK(d(0) == doctest::Approx(to_a).epsilon(1e-12));
  CHECK(d(1) == doctest::Approx(to_b).epsilon(1e-12));
}

TEST_CASE("height distances do not change under a planar motion of the test, and recognise own training data") {
  Rng rng(11);
  std::vector<TouchSet> objects;
  for (int o = 0; o < 4; ++o) {
    std::vector<Eigen::Vector3d> p, n;
    for (int i = 0; i < 30; ++i) {
      p.emplace_back(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), 0.005 * (1 + o) + rng.uniform(0, 0.004));
      n.push_back(normal(rng.uniform(0, 0.3 * (1 + o)), rng.uniform(-kPi, kPi)));
    }
    objects.push_back(touches(p, n));
  }
  HeightClassifier height;
  height.fit(objects, 0);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index o = 0; o < 4; ++o) {
    const TouchSet test = select_touches(objects[static_cast<std::size_t>(o)], std::vector<Index>{2, 7, 11, 19});
    Eigen::VectorXd d(4), moved_d(4);
    height.distances(test, d);
    CHECK(d(o) == 0.0);
    CHECK(decide(d) == o);
    TouchSet moved = test;
    moved.positions = (turn * test.positions).colwise() + Eigen::Vector3d(0.4, -0.3, 0.0);
    moved.normals = turn * test.normals;
    height.distances(moved, moved_d);
    CHECK((moved_d - d).cwiseAbs().maxCoeff() < 1e-15);
    // Lifting the test by 5 mm is no planar motion: its own object is no longer at distance 0.
    moved.positions.row(2).array() += 0.005;
    height.distances(moved, moved_d);
    CHECK(moved_d(o) > 0.0);
  }
}

TEST_CASE("the height classifier names what it is missing") {
  HeightClassifier height;
  const TouchSet good = touches({Eigen::Vector3d::Zero()}, {normal(0, 0)});
  TouchSet bare = good;
  bare.normals.resize(3, 0);
  CHECK_THROWS_WITH_AS(height.fit({good, bare}, 0),
                       "objects[1].normals: the height classifier needs the pad orientation of every touch (dataset "
                       "columns qw, qx, qy, qz)",
                       EmptyInput);
  CHECK_THROWS_AS(height.fit({}, 0), EmptyInput);
  height.fit({good}, 0);
  Eigen::VectorXd d(1);
  CHECK_THROWS_WITH_AS(height.distances(bare, d),
                       "test.normals: the height classifier needs the pad orientation of every touch (dataset columns "
                       "qw, qx, qy, qz)",
                       EmptyInput);
  Eigen::VectorXd wrong(2);
  CHECK_THROWS_AS(height.distances(good, wrong), DimensionMismatch);
  height.tilt_scale = 0;
  CHECK_THROWS_WITH_AS(height.fit({good}, 0), "tilt_scale: must be finite and > 0, got 0.000000", InvalidArgument);
  height.tilt_scale = std::nan("");
  CHECK_THROWS_AS(height.fit({good}, 0), InvalidArgument);
}
