// SPDX-License-Identifier: MIT
// Pad normals of touches and the registration-free height classifier.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "../support/wts_dataset.hpp"

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
  CHECK(height_and_tilt(p, normal(1e-9, 0.3))(1) == doctest::Approx(1e-9).epsilon(1e-6).scale(0));
}

TEST_CASE("touch tables carry the pad normals when every contact frame has an orientation") {
  Dataset ds = test::wts_dataset();
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
  CHECK_THROWS_WITH_AS(longer.validate("s"), "s.normals: column 1 is not a unit vector (norm 2)",
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
  CHECK_THROWS_WITH_AS(height.fit({good}, 0), "tilt_scale: must be finite and positive, got 0", InvalidArgument);
  height.tilt_scale = std::nan("");
  CHECK_THROWS_AS(height.fit({good}, 0), InvalidArgument);
}

namespace {

/// `touches` with contact points: touch i gets `patches[i]`.
TouchSet with_contacts(TouchSet s, const std::vector<Eigen::Matrix3Xd>& patches) {
  s.contact_offsets = {0};
  Index total = 0;
  for (const auto& p : patches) total += p.cols();
  s.contact_points.resize(3, total);
  Index k = 0;
  for (const auto& p : patches) {
    s.contact_points.middleCols(k, p.cols()) = p;
    k += p.cols();
    s.contact_offsets.push_back(k);
  }
  return s;
}

/// A flat grid of nx x ny points at `pitch` around `centre`, in the plane
/// spanned by `u` and `v`.
Eigen::Matrix3Xd grid(int nx, int ny, double pitch, const Eigen::Vector3d& centre, const Eigen::Vector3d& u,
                      const Eigen::Vector3d& v) {
  Eigen::Matrix3Xd p(3, nx * ny);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      p.col(i * ny + j) = centre + pitch * ((i - 0.5 * (nx - 1)) * u + (j - 0.5 * (ny - 1)) * v);
  return p;
}

/// Standard deviation of n points at unit spacing, centred: sqrt((n^2 - 1) / 12).
double grid_sd(int n, double pitch) { return pitch * std::sqrt((n * n - 1) / 12.0); }

}  // namespace

TEST_CASE("contact_extents: the patch's principal standard deviations, largest first, whatever its pose") {
  const double pitch = 0.0034;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  // A 6 x 3 patch lying flat: length along x, width along y.
  const Eigen::Vector2d flat = contact_extents(grid(6, 3, pitch, Eigen::Vector3d(0.1, 0.2, 0.03), x, y));
  CHECK(flat(0) == doctest::Approx(grid_sd(6, pitch)).epsilon(1e-12));
  CHECK(flat(1) == doctest::Approx(grid_sd(3, pitch)).epsilon(1e-12));
  // The same patch turned about every axis and moved: the same extents.
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const Eigen::Vector2d turned = contact_extents(grid(6, 3, pitch, Eigen::Vector3d(-5, 7, 2), r * x, r * y));
  CHECK((turned - flat).norm() < 1e-12);
  // A line of taxels along an edge: no width. One point, or none: no patch.
  const Eigen::Vector2d line = contact_extents(grid(1, 5, pitch, Eigen::Vector3d::Zero(), x, y));
  CHECK(line(0) == doctest::Approx(grid_sd(5, pitch)).epsilon(1e-12));
  CHECK(line(1) < 1e-12);
  CHECK(contact_extents(Eigen::Matrix3Xd::Constant(3, 1, 0.4)) == Eigen::Vector2d::Zero());
  CHECK(contact_extents(Eigen::Matrix3Xd(3, 0)) == Eigen::Vector2d::Zero());
  // Far from the origin (1 km) a millimetre patch keeps its size.
  const Eigen::Vector2d far = contact_extents(grid(6, 3, pitch, Eigen::Vector3d(1000, -1000, 0.03), x, y));
  CHECK(far(0) == doctest::Approx(flat(0)).epsilon(1e-6));
  CHECK(far(1) == doctest::Approx(flat(1)).epsilon(1e-6));
  // Spreads whose covariance overflows (it gave NaN, read as 0) or
  // underflows (it gave 0) keep their size, relative to it (scale(0): a
  // plain Approx takes 0 for 1e-160); and so do points whose sum overflows
  // (at 1e308 m, 3.4e302 m apart).
  for (const auto& spread_at : std::vector<std::pair<double, double>>{
           {1e160, 1e160}, {1e300, 1e300}, {1e-160, 1e-160}, {1e-300, 1e-300}, {1e305, 1e308}}) {
    const double s = spread_at.first, at = spread_at.second;
    CAPTURE(s);
    const Eigen::Vector2d e = contact_extents(grid(6, 3, pitch * s, Eigen::Vector3d(at, 0, 0), x, y));
    CHECK(e(0) == doctest::Approx(grid_sd(6, pitch * s)).epsilon(1e-9).scale(0));
    CHECK(e(1) == doctest::Approx(grid_sd(3, pitch * s)).epsilon(1e-9).scale(0));
  }
  // Coincident points: no patch, not NaN.
  CHECK(contact_extents(Eigen::Matrix3Xd::Constant(3, 4, 0.4)) == Eigen::Vector2d::Zero());
  Eigen::Matrix3Xd bad = grid(2, 2, pitch, Eigen::Vector3d::Zero(), x, y);
  bad(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(contact_extents(bad), NonFiniteValue);
}

TEST_CASE("the height classifier refuses coordinates whose squared distances overflow, naming the touch") {
  HeightClassifier h;
  h.fit({touches({Eigen::Vector3d::Zero()}, {normal(0, 0)}), touches({Eigen::Vector3d(0, 0, 0.1)}, {normal(0, 0)})}, 0);
  Eigen::VectorXd d(2);
  // A height of 1e160 m passes TouchSet::validate (it is finite) but its
  // squared distance is inf: it gave {inf, inf}.
  const TouchSet far = touches({Eigen::Vector3d(0, 0, 0.02), Eigen::Vector3d(0, 0, 1e160)}, {normal(0, 0), normal(0, 0)});
  try {
    h.distances(far, d);
    FAIL("a height of 1e160 m was taken");
  } catch (const InvalidArgument& e) {
    CHECK(std::string(e.argument()) == "test.positions (the height z)");
    CHECK(std::string(e.what()).find("touch 1 gives 1e+160") != std::string::npos);
  }
  // A scale that blows a tilt up as far is named with the scales.
  HeightClassifier steep;
  steep.tilt_scale = 1e200;
  try {
    steep.fit({touches({Eigen::Vector3d::Zero()}, {normal(kPi / 2, 0)})}, 0);
    FAIL("a tilt of 1.6e200 was taken");
  } catch (const InvalidArgument& e) {
    CHECK(std::string(e.argument()) == "objects[0].normals (the tilt times tilt_scale)");
    CHECK(std::string(e.what()).find("tilt_scale 1e+200") != std::string::npos);
  }
  // A patch blown up as far by contact_scale is named as its length (the
  // larger extent, so the first beyond range).
  HeightClassifier wide;
  wide.contact_scale = 1e200;
  const Eigen::Matrix3Xd square = grid(3, 3, 0.01, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY());
  const TouchSet patch = with_contacts(touches({Eigen::Vector3d::Zero()}, {normal(0, 0)}), {square});
  CHECK_THROWS_WITH_AS(wide.fit({patch}, 0),
                       doctest::Contains("objects[0].contact_points (the patch length times contact_scale): touch 0 gives"),
                       InvalidArgument);
  // Within range, the largest heights still give finite distances.
  const TouchSet high = touches({Eigen::Vector3d(0, 0, 1e149)}, {normal(0, 0)});
  h.distances(high, d);
  CHECK(d.allFinite());
}

TEST_CASE("height_contact: heights, tilts and contact extents; without the patch, the height classifier exactly") {
  const double pitch = 0.0034, c = 0.5, s = 0.01;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  // Both objects are touched on a top face at 20 mm; object 0 is a broad
  // face (6 x 6 taxels pressed), object 1 a thin handle (6 x 1).
  const TouchSet broad = with_contacts(touches({{0.0, 0.0, 0.020}}, {normal(0, 0)}),
                                       {grid(6, 6, pitch, Eigen::Vector3d(0, 0, 0.020), x, y)});
  const TouchSet thin = with_contacts(touches({{0.2, 0.0, 0.020}}, {normal(0, 0)}),
                                      {grid(6, 1, pitch, Eigen::Vector3d(0.2, 0, 0.020), x, y)});
  // The test: a thin contact at 21 mm, elsewhere on the table and turned.
  const Eigen::Vector3d u = Eigen::Vector3d(1, 1, 0).normalized(), v = Eigen::Vector3d(-1, 1, 0).normalized();
  const TouchSet test = with_contacts(touches({{0.5, 0.4, 0.021}}, {normal(0, 0)}),
                                      {grid(6, 1, pitch, Eigen::Vector3d(0.5, 0.4, 0.021), u, v)});

  HeightClassifier plain;
  plain.fit({broad, thin}, 0);
  Eigen::VectorXd d_plain(2);
  plain.distances(test, d_plain);
  CHECK(plain.name() == "height");
  CHECK(d_plain(0) == doctest::Approx(1e-6).epsilon(1e-9));  // only the 1 mm of height
  CHECK(d_plain(1) == doctest::Approx(1e-6).epsilon(1e-9));

  HeightClassifier contact;
  contact.contact_scale = c;
  CHECK(contact.name() == "height_contact");
  contact.fit({broad, thin}, 0);
  Eigen::VectorXd d(2);
  contact.distances(test, d);
  const double width = grid_sd(6, pitch);  // the broad face's second extent; the thin one has none
  CHECK(d(0) == doctest::Approx(1e-6 + c * c * width * width).epsilon(1e-9));
  CHECK(d(1) == doctest::Approx(1e-6).epsilon(1e-9));
  CHECK(decide(d) == 1);

  // With contact_scale 0 the contact points change nothing, to the last bit,
  // and match the two-coordinate sum computed here.
  TouchSet other = test;
  other.contact_points *= 3.0;
  Eigen::VectorXd d_other(2);
  plain.distances(other, d_other);
  CHECK(d_other(0) == d_plain(0));
  CHECK(d_other(1) == d_plain(1));
  const double dz = 0.021 - 0.020, dt = s * 0.0;
  CHECK(d_plain(0) == dz * dz + dt * dt);

  contact.label = "mine";
  CHECK(contact.name() == "mine");

  // Distances use the scales of the fit: changing them afterwards changes
  // nothing until the next fit (no mix of a 2-coordinate reference with
  // 4-coordinate tests or the reverse).
  plain.contact_scale = c;
  plain.tilt_scale = 1;
  contact.contact_scale = 0;
  Eigen::VectorXd d_plain_after(2), d_after(2);
  plain.distances(test, d_plain_after);
  contact.distances(test, d_after);
  CHECK(d_plain_after == d_plain);
  CHECK(d_after == d);
  contact.fit({broad, thin}, 0);  // now without the contact patch
  contact.distances(test, d_after);
  CHECK(d_after == d_plain);
}

TEST_CASE("height_contact distances do not change under a planar motion of the test") {
  Rng rng(5);
  const double pitch = 0.0034;
  std::vector<TouchSet> objects;
  for (int o = 0; o < 3; ++o) {
    std::vector<Eigen::Vector3d> p, n;
    std::vector<Eigen::Matrix3Xd> patches;
    for (int i = 0; i < 20; ++i) {
      p.emplace_back(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), 0.01 + rng.uniform(0, 0.004));
      n.push_back(normal(rng.uniform(0, 0.5), rng.uniform(-kPi, kPi)));
      const Eigen::Matrix3d pad = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d(0, 0, -1), n.back()).toRotationMatrix();
      patches.push_back(grid(2 + (o + i) % 5, 1 + o, pitch, p.back(), pad.col(0), pad.col(1)));
    }
    objects.push_back(with_contacts(touches(p, n), patches));
  }
  HeightClassifier contact;
  contact.contact_scale = 1;
  contact.fit(objects, 0);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index o = 0; o < 3; ++o) {
    const TouchSet test = select_touches(objects[static_cast<std::size_t>(o)], std::vector<Index>{1, 4, 9});
    Eigen::VectorXd d(3), moved_d(3);
    contact.distances(test, d);
    CHECK(d(o) == 0.0);
    TouchSet moved = test;
    const Eigen::Vector3d shift(0.3, 0.2, 0.0);
    moved.positions = (turn * test.positions).colwise() + shift;
    moved.normals = turn * test.normals;
    moved.contact_points = (turn * test.contact_points).colwise() + shift;
    contact.distances(moved, moved_d);
    CHECK((moved_d - d).cwiseAbs().maxCoeff() < 1e-12);
    // Dropping the touches' contact points is refused, not read as patches of size 0.
    moved.contact_points.resize(3, 0);
    moved.contact_offsets.clear();
    CHECK_THROWS_WITH_AS(contact.distances(moved, moved_d),
                         "test.contact_points: the height_contact classifier needs the contact points of the touches "
                         "(the pressed taxels placed by the pad orientation)",
                         EmptyInput);
  }
}

TEST_CASE("height_contact names bad settings and what it is missing") {
  HeightClassifier contact;
  contact.contact_scale = -0.5;
  const TouchSet good = with_contacts(touches({Eigen::Vector3d::Zero()}, {normal(0, 0)}), {Eigen::Matrix3Xd::Zero(3, 2)});
  CHECK_THROWS_WITH_AS(contact.fit({good}, 0), "contact_scale: must be finite and >= 0, got -0.5", InvalidArgument);
  contact.contact_scale = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(contact.fit({good}, 0), InvalidArgument);
  contact.contact_scale = 1;
  TouchSet bare = good;
  bare.contact_points.resize(3, 0);
  bare.contact_offsets.clear();
  CHECK_THROWS_WITH_AS(contact.fit({good, bare}, 0),
                       "objects[1].contact_points: the height_contact classifier needs the contact points of the "
                       "touches (the pressed taxels placed by the pad orientation)",
                       EmptyInput);
  TouchSet unoriented = good;
  unoriented.normals.resize(3, 0);
  CHECK_THROWS_WITH_AS(contact.fit({unoriented}, 0),
                       "objects[0].normals: the height_contact classifier needs the pad orientation of every touch "
                       "(dataset columns qw, qx, qy, qz)",
                       EmptyInput);
  // A touch with no contact point among others that have some: extents (0, 0).
  TouchSet mixed = with_contacts(touches({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, {normal(0, 0), normal(0, 0)}),
                                 {Eigen::Matrix3Xd(3, 0), grid(3, 3, 0.01, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                                               Eigen::Vector3d::UnitY())});
  contact.fit({mixed}, 0);
  CHECK(contact.embed(mixed, "m").col(0).tail<2>() == Eigen::Vector2d::Zero());
  CHECK(contact.embed(mixed, "m")(2, 1) == doctest::Approx(grid_sd(3, 0.01)).epsilon(1e-12));
}

TEST_CASE("the height classifier refuses touch sets that TouchSet::validate refuses, naming the argument") {
  HeightClassifier height;
  const TouchSet good = touches({Eigen::Vector3d(0, 0, 0.01), Eigen::Vector3d(0, 0, 0.02)}, {normal(0, 0), normal(0.3, 1)});
  TouchSet longer = good;  // a normal of length 2: its tilt would still read as 0.3 rad
  longer.normals.col(1) *= 2.0;
  CHECK_THROWS_WITH_AS(height.fit({good, longer}, 0), "objects[1].normals: column 1 is not a unit vector (norm 2)",
                       InvalidArgument);
  height.fit({good}, 0);
  Eigen::VectorXd d(1);
  CHECK_THROWS_WITH_AS(height.distances(longer, d), "test.normals: column 1 is not a unit vector (norm 2)",
                       InvalidArgument);
  TouchSet nan = good;
  nan.positions(0, 0) = std::numeric_limits<double>::quiet_NaN();  // x: not read by the classifier
  CHECK_THROWS_AS(height.distances(nan, d), NonFiniteValue);
}
