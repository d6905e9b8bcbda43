// SPDX-License-Identifier: MIT
// Free points of touches and the occupancy classifier: its placement grid,
// what the free points decide, pool reuse and its errors.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/live_session.hpp"
#include "iclap/recognition/occupancy_classifier.hpp"
#include "iclap/recognition/touch_table.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "../support/wts_dataset.hpp"

using namespace iclap;

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kPitch = 0.0034;

/// A box on the table, `length` along x and `width` along y, `height` tall,
/// centred at `centre` (x, y).
struct Box {
  double length, width, height;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  bool over(double x, double y) const {
    return std::abs(x - centre.x()) <= length / 2 && std::abs(y - centre.y()) <= width / 2;
  }
};

/// A 14 x 6 pad's frame: its centre, its normal (into the surface) and
/// the directions of its rows (u) and columns (v).
struct PadFrame {
  Eigen::Vector3d centre, normal, u, v;
};

/// Touches of a 14 x 6 pad at `frame(i)` for i < n; a taxel p is pressed (a
/// contact point) where `pressed(p)`, else free. Calls frame once per touch,
/// then pressed once per taxel, rows first.
template <typename Frame, typename Pressed>
TouchSet pads(Index n, Frame&& frame, Pressed&& pressed_at) {
  TouchSet s;
  s.positions.resize(3, n);
  s.normals.resize(3, n);
  std::vector<Eigen::Vector3d> pressed, free;
  s.contact_offsets = {0};
  s.free_offsets = {0};
  for (Index i = 0; i < n; ++i) {
    const PadFrame f = frame(i);
    s.positions.col(i) = f.centre;
    s.normals.col(i) = f.normal;
    for (int r = 0; r < 14; ++r)
      for (int k = 0; k < 6; ++k) {
        const Eigen::Vector3d p = f.centre + (r - 6.5) * kPitch * f.u + (k - 2.5) * kPitch * f.v;
        (pressed_at(p) ? pressed : free).push_back(p);
      }
    s.contact_offsets.push_back(static_cast<Index>(pressed.size()));
    s.free_offsets.push_back(static_cast<Index>(free.size()));
  }
  s.contact_points.resize(3, static_cast<Index>(pressed.size()));
  for (std::size_t k = 0; k < pressed.size(); ++k) s.contact_points.col(static_cast<Index>(k)) = pressed[k];
  s.free_points.resize(3, static_cast<Index>(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k) s.free_points.col(static_cast<Index>(k)) = free[k];
  return s;
}

/// Touches of a 14 x 6 pad pressing straight down on the top face of `box`
/// with its centre at each of `centres` (x, y): a taxel over the box is
/// pressed (a contact point), the others are free points, all at the top's
/// height. The pad's rows run along world x, its columns along world y.
TouchSet pad_touches(const Box& box, const std::vector<Eigen::Vector2d>& centres) {
  return pads(
      static_cast<Index>(centres.size()),
      [&](Index i) {
        const Eigen::Vector2d& c = centres[static_cast<std::size_t>(i)];
        return PadFrame{Eigen::Vector3d(c.x(), c.y(), box.height), Eigen::Vector3d(0, 0, -1), Eigen::Vector3d::UnitX(),
                        Eigen::Vector3d::UnitY()};
      },
      [&](const Eigen::Vector3d& p) { return box.over(p.x(), p.y()); });
}

/// An occupancy classifier that searches the identity placement only, with
/// a slab `back` metres deep behind the pad.
OccupancyClassifier one_placement(double back) {
  OccupancyClassifier c;
  c.placements.max_shift = 0;
  c.placements.max_yaw = 0;
  c.back_depth = back;
  return c;
}

/// Pad centres on a grid over [x0, x1] x [y0, y1], `step` apart.
std::vector<Eigen::Vector2d> grid_of(double x0, double x1, double y0, double y1, double step) {
  std::vector<Eigen::Vector2d> out;
  for (double x = x0; x <= x1 + 1e-12; x += step)
    for (double y = y0; y <= y1 + 1e-12; y += step) out.emplace_back(x, y);
  return out;
}

/// `s` moved by the planar motion (shift, yaw about the origin).
TouchSet moved(TouchSet s, const Eigen::Vector2d& shift, double yaw) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto move = [&](Eigen::Matrix3Xd& m) {
    m = R * m;
    m.topRows<2>().colwise() += shift;
  };
  move(s.positions);
  move(s.contact_points);
  move(s.free_points);
  s.normals = R * s.normals;
  return s;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// The two look-alikes: equal height and flat tops, 60 x 40 mm and 100 x 60 mm.
const Box kSmall{0.06, 0.04, 0.03};
const Box kLarge{0.10, 0.06, 0.03};

/// References from pads all over each top and past its edges (training
/// explorations that saw both boxes whole).
std::vector<TouchSet> training() {
  return {pad_touches(kSmall, grid_of(-0.04, 0.04, -0.03, 0.03, 0.01)),
          pad_touches(kLarge, grid_of(-0.06, 0.06, -0.04, 0.04, 0.01))};
}

}  // namespace

TEST_CASE("make_touch_table and live touches carry the free points: the taxels that felt nothing") {
  Dataset ds = test::wts_dataset();
  Frame f;
  f.object = "a";
  f.position = Eigen::Vector3d(0.01, 0.02, 0.03);
  f.pressures = Eigen::MatrixXd::Zero(14, 6);
  f.pressures.block(0, 0, 5, 6).setConstant(100);  // rows 0-4 pressed
  f.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()));  // straight down
  ds.frames = {f};
  const TouchTable t = make_touch_table(ds, RawPressures<float>{}, 20.0);
  REQUIRE(t.touches.has_free());
  CHECK(t.touches.contacts_of(0) == 30);
  CHECK(t.touches.free_of(0) == 54);
  // Together they are the whole grid, each taxel once.
  std::vector<Eigen::Vector3d> all;
  append_contact_points(f, 20.0, kPitch, all);
  append_free_points(f, 20.0, kPitch, all);
  CHECK(all.size() == 84);
  for (Index k = 0; k < 54; ++k) {
    const Eigen::Vector3d p = t.touches.free_points.col(k);
    CHECK(p.z() == doctest::Approx(0.03));
    // Free taxels are rows 5..13: along +x from the pad centre's row 6.5.
    CHECK(p.x() > 0.01 + (5 - 6.5) * kPitch - 1e-9);
  }
  const LiveTouch live = live_touch_of(f, 20.0, kPitch, Eigen::VectorXf(), 0);
  CHECK(live.contact_points.cols() == 30);
  CHECK(live.free_points.cols() == 54);
  CHECK(live.free_points == t.touches.free_points);
  const LiveTouch again = live_touch_of(t.touches, 0, 0);
  CHECK(again.free_points == t.touches.free_points);
  // Without an orientation there is nowhere to put them.
  ds.frames[0].orientation.reset();
  CHECK(!make_touch_table(ds, RawPressures<float>{}, 20.0).touches.has_free());
}

TEST_CASE("touch sets: free points are selected with their touches and checked like contact points") {
  const TouchSet s = pad_touches(kSmall, {{0.0, 0.0}, {0.028, 0.0}, {-0.03, 0.015}});
  CHECK_NOTHROW(s.validate("s"));
  CHECK(s.free_of(0) + s.contacts_of(0) == 84);
  const TouchSet two = select_touches(s, std::vector<Index>{2, 1});
  CHECK(two.free_of(0) == s.free_of(2));
  CHECK(two.free_of(1) == s.free_of(1));
  CHECK(two.free_points.leftCols(s.free_of(2)) == s.free_points.middleCols(s.free_offsets[2], s.free_of(2)));
  TouchSet bad = s;
  bad.free_offsets[1] = bad.free_offsets[2] + 1;  // not rising
  CHECK(error_of([&] { bad.validate("s"); }).find("s.free_offsets") != std::string::npos);
  bad = s;
  bad.free_offsets.pop_back();
  CHECK(error_of([&] { bad.validate("s"); }).find("s.free_offsets (touches + 1)") != std::string::npos);
  bad = s;
  bad.free_points(2, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK(error_of([&] { bad.validate("s"); }).find("s.free_points") != std::string::npos);
}

TEST_CASE("PlanarPlacements: a bounded grid, identity first, every motion within the bounds") {
  PlanarPlacements p;
  const Eigen::Matrix3Xd g = p.grid();
  CHECK(g.cols() == 21 * 5);  // shifts of 4 mm within 10 mm (21), turns of 5 degrees within 10 (5)
  CHECK(g.col(0) == Eigen::Vector3d::Zero());
  for (Index k = 0; k < g.cols(); ++k) {
    CHECK(g.col(k).head<2>().norm() <= p.max_shift + 1e-12);
    CHECK(std::abs(g(2, k)) <= p.max_yaw + 1e-12);
    if (k > 0) CHECK(g.col(k - 1).head<2>().squaredNorm() <= g.col(k).head<2>().squaredNorm() + 1e-18);
  }
  p.max_shift = 0;
  p.max_yaw = 0;
  CHECK(p.grid().cols() == 1);
  p.max_yaw = 2 * kPi / 180;
  p.yaw_step = kPi / 180;
  CHECK(p.grid().cols() == 5);
  PlanarPlacements bad;
  bad.shift_step = 0;
  CHECK(error_of([&] { bad.grid("placements"); }).find("placements.shift_step") != std::string::npos);
  bad = PlanarPlacements{};
  bad.max_yaw = 4;
  CHECK(error_of([&] { bad.validate("p"); }).find("p.max_yaw") != std::string::npos);
  bad = PlanarPlacements{};
  bad.max_shift = 1;
  bad.shift_step = 1e-3;  // 2001^2 shifts
  CHECK(error_of([&] { bad.validate(); }).find("use larger steps") != std::string::npos);
  // validate counts the steps as grid() takes them: 0.3 / 0.1 is
  // 2.9999999999999996, which the grid rounds to 3 rings of shifts. Counted
  // as 2, this grid passed with 104429 placements, beyond kMaxPlacements.
  bad = PlanarPlacements{};
  bad.max_shift = 0.3;
  bad.shift_step = 0.1;
  bad.max_yaw = kPi;
  bad.yaw_step = kPi / 1800;  // 3601 turns
  CHECK(error_of([&] { bad.validate(); }).find("up to 176449 placements") != std::string::npos);
  bad.yaw_step = kPi / 1000;  // 2001 turns x 49 shifts, 29 of them within the disc
  CHECK(bad.grid().cols() == 29 * 2001);
  CHECK(bad.grid().cols() <= PlanarPlacements::kMaxPlacements);
}

TEST_CASE("occupancy: where a pad felt nothing tells look-alikes apart that the pressed taxels cannot") {
  OccupancyClassifier c;
  c.fit(training(), 0);
  REQUIRE(c.objects() == 2);
  CHECK(c.placement_count() == 105);
  // Tests on the overlap of the two tops, near the small box's long edges:
  // every pressed taxel lies on both references, but the pads overhang the
  // small box's edges where the large box's references were pressed.
  const TouchSet small_test = pad_touches(kSmall, {{0.02, 0.0}, {-0.02, 0.0}, {0.0, 0.0}});
  // Tests out where the large box continues and the small box's training
  // pads felt nothing.
  const TouchSet large_test = pad_touches(kLarge, {{0.04, 0.0}, {-0.035, 0.01}, {0.045, -0.02}});
  Eigen::VectorXd d(2);
  c.distances(small_test, d);
  CHECK(d(0) < d(1));
  c.distances(large_test, d);
  CHECK(d(1) < d(0));
  // Without the free points (gamma = 0) the small box's test, in place,
  // sits on both references equally well: the pressed taxels alone cannot
  // decide.
  OccupancyClassifier blind;
  blind.conflict_weight = 0;
  blind.placements.max_shift = 0;  // both at the same placement
  blind.placements.max_yaw = 0;
  blind.fit(training(), 0);
  blind.distances(small_test, d);
  CHECK(d(0) == doctest::Approx(d(1)).epsilon(1e-9));
}

TEST_CASE("occupancy: the slab behind the pad (back_depth) contradicts a touch pressed above felt surface") {
  // Two boxes of one footprint, 30 and 35 mm tall, their tops touched all
  // over; one placement only, and the test pad's taxels right under the
  // training pads' (the same lattice), so every charge can be counted.
  const Box low{0.10, 0.06, 0.030}, high{0.10, 0.06, 0.035};
  std::vector<Eigen::Vector2d> centres;
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b) centres.emplace_back(7 * a * kPitch, 3 * b * kPitch);
  const std::vector<TouchSet> objects = {pad_touches(low, centres), pad_touches(high, centres)};
  const TouchSet test = pad_touches(high, {{0.0, 0.0}});  // all 84 taxels pressed, on the tall top
  REQUIRE(test.contact_points.cols() == 84);
  OccupancyClassifier plain = one_placement(0), backed = one_placement(0.006);
  CHECK(plain.back_layers().empty());
  CHECK(backed.back_layers() == std::vector<double>{0.003, 0.006});
  plain.fit(objects, 0);
  backed.fit(objects, 0);
  Eigen::VectorXd d0(2), d1(2);
  plain.distances(test, d0);
  backed.distances(test, d1);
  // Against the low box each pressed taxel is 5 mm above felt surface (a
  // miss, tau^2) and, with the slab, 1 mm under the 6 mm layer above it: a
  // contradiction, gamma tau^2 more for each of the 84.
  const double tau2 = plain.truncation * plain.truncation;
  CHECK(d0(0) == doctest::Approx(84 * tau2).epsilon(1e-5).scale(0));
  CHECK(d1(0) - d0(0) == doctest::Approx(84 * plain.conflict_weight * tau2).epsilon(1e-5).scale(0));
  // Against its own box nothing changes: its slab starts 3 mm above the
  // top, beyond the free radius, and so does the test pad's.
  CHECK(d1(1) == d0(1));
  // A test pressed on the low top: against the tall box, the test pad's own
  // slab cuts through the tall top (its 6 mm layer 1 mm above it, its 3 mm
  // layer 2 mm under it): a contradiction for each of the 84 taxels of one
  // layer at least, of both at most.
  const TouchSet low_test = pad_touches(low, {{0.0, 0.0}});
  plain.distances(low_test, d0);
  backed.distances(low_test, d1);
  const double step = plain.conflict_weight * tau2;
  CHECK(d1(1) - d0(1) >= 84 * step * (1 - 1e-5));
  CHECK(d1(1) - d0(1) <= 168 * step * (1 + 1e-5));
  CHECK(d1(0) == d0(0));
  // The pool path sums the same costs, slab included.
  const TouchSet pool = pad_touches(high, {{0.0, 0.0}, {0.01, 0.0}, {-0.01, 0.01}});
  const auto prepared = backed.prepare_pool(pool);
  Eigen::VectorXd whole(2), part(2);
  backed.pool_distances(pool, prepared.get(), {2, 0}, part);
  backed.distances(select_touches(pool, std::vector<Index>{2, 0}), whole);
  CHECK(part == whole);

  // The layers: m = ceil(b / (1.5 rho)) of them, evenly down to b.
  OccupancyClassifier c;
  c.back_depth = 0.001;
  CHECK(c.back_layers() == std::vector<double>{0.001});
  c.back_depth = 0.0031;
  CHECK(c.back_layers() == std::vector<double>{0.00155, 0.0031});
  c.back_depth = 16 * c.free_radius;
  CHECK(c.back_layers().size() == 11);
  // Refused: negative, not a number, deeper than 16 free radii.
  for (const double bad : {-1e-3, std::numeric_limits<double>::quiet_NaN(), 16.5 * c.free_radius}) {
    c.back_depth = bad;
    CHECK(error_of([&] { c.validate(); }).find("back_depth: must be >= 0 and at most 16 free radii (0.032 m)") == 0);
  }
  // The slab needs the pad normals, of the training touches and of a test.
  std::vector<TouchSet> bare = objects;
  bare[1].normals.resize(3, 0);
  backed = one_placement(0.006);
  CHECK(error_of([&] { backed.fit(bare, 0); }).find("objects[1].normals") == 0);
  plain.fit(bare, 0);  // without the slab they are not read
  backed.fit(objects, 0);
  TouchSet no_normals = test;
  no_normals.normals.resize(3, 0);
  CHECK(error_of([&] { backed.distances(no_normals, d1); }).find("test.normals") == 0);
  CHECK(error_of([&] { backed.prepare_pool(no_normals); }).find("pool.normals") == 0);
  plain.distances(no_normals, d0);
}

namespace {

/// Touches of a tilted 14 x 6 pad at random heights in [z0, z1] metres,
/// random pad normals up to 60 degrees from straight down, and random
/// taxels pressed: points of every kind on both sides of any height.
TouchSet random_pad_touches(Rng& rng, Index n, double z0, double z1) {
  return pads(
      n,
      [&](Index) {
        const Eigen::Vector3d centre(rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), rng.uniform(z0, z1));
        const double tilt = rng.uniform(0, kPi / 3), heading = rng.uniform(-kPi, kPi);
        const Eigen::Vector3d normal(std::sin(tilt) * std::cos(heading), std::sin(tilt) * std::sin(heading),
                                     -std::cos(tilt));
        const Eigen::Vector3d u = normal.unitOrthogonal();
        return PadFrame{centre, normal, u, normal.cross(u)};
      },
      [&](const Eigen::Vector3d&) { return rng.uniform() < 0.3; });
}

/// The classifier's distances written out from its documentation with
/// TruncatedDistanceField alone, for the identity placement (c must search
/// only that one), in the classifier's order of summation: every contact
/// point's truncated squared distance plus a contradiction where free
/// evidence is nearer, and a contradiction for every free point and every
/// slab point (taxels moved back along the pad normal to each layer)
/// nearer felt surface than free evidence. `charged` counts the
/// contradictions of free and slab points.
Eigen::VectorXd formula_distances(const OccupancyClassifier& c, const std::vector<TouchSet>& objects,
                                  const TouchSet& test, Index& charged) {
  const std::vector<double> layers = c.back_layers();
  // Calls f on the slab points of touch i of s, for every layer.
  auto slab = [&](const TouchSet& s, Index i, const std::function<void(const Eigen::Vector3d&)>& f) {
    const auto u = static_cast<std::size_t>(i);
    for (const double d : layers) {
      for (Index k = s.contact_offsets[u]; k < s.contact_offsets[u + 1]; ++k) f(s.contact_points.col(k) - d * s.normals.col(i));
      for (Index k = s.free_offsets[u]; k < s.free_offsets[u + 1]; ++k) f(s.free_points.col(k) - d * s.normals.col(i));
    }
  };
  const auto cap = static_cast<float>(c.truncation * c.truncation);
  const auto rho2 = static_cast<float>(c.free_radius * c.free_radius);
  const double penalty = c.conflict_weight * static_cast<double>(cap);
  Eigen::VectorXd out(static_cast<Index>(objects.size()));
  charged = 0;
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const TouchSet& o = objects[j];
    std::vector<Eigen::Vector3d> f;
    for (Index k = 0; k < o.free_points.cols(); ++k) f.push_back(o.free_points.col(k));
    for (Index i = 0; i < o.size(); ++i) slab(o, i, [&](const Eigen::Vector3d& q) { f.push_back(q); });
    Eigen::Matrix3Xd fm(3, static_cast<Index>(f.size()));
    for (std::size_t k = 0; k < f.size(); ++k) fm.col(static_cast<Index>(k)) = f[k];
    const TruncatedDistanceField occupied(o.contact_points, {c.voxel, c.truncation});
    const TruncatedDistanceField freed(fm, {c.voxel, c.free_radius});
    double e = 0;
    for (Index i = 0; i < test.size(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      double cost = 0;
      for (Index k = test.contact_offsets[u]; k < test.contact_offsets[u + 1]; ++k) {
        const Eigen::Vector3d q = test.contact_points.col(k);
        const float dn = occupied.squared_distance(q), df = freed.squared_distance(q);
        cost += static_cast<double>(dn);
        if (df < dn && df < rho2) cost += penalty;
      }
      auto free_point = [&](const Eigen::Vector3d& q) {
        const float dn = occupied.node_squared_distance(q);
        if (dn < rho2 && dn < freed.node_squared_distance(q)) {
          cost += penalty;
          ++charged;
        }
      };
      for (Index k = test.free_offsets[u]; k < test.free_offsets[u + 1]; ++k) free_point(test.free_points.col(k));
      slab(test, i, free_point);
      e += cost;
    }
    out(static_cast<Index>(j)) = e;
  }
  return out;
}

}  // namespace

TEST_CASE("occupancy: the distances are the formula's, point by point, slab and free points included") {
  // The classifier skips the free and slab points that lie too high or too
  // low to be charged under any placement; these tests reach from below
  // the objects' felt surface to well above it, so that many of them are
  // skipped and many charged.
  Rng rng(2018);
  const std::vector<TouchSet> objects = {random_pad_touches(rng, 30, 0.020, 0.030),
                                         random_pad_touches(rng, 30, 0.026, 0.034)};
  for (const double back : {0.0, 0.006}) {
    CAPTURE(back);
    OccupancyClassifier c = one_placement(back);
    c.fit(objects, 0);
    REQUIRE(c.placement_count() == 1);
    const TouchSet test = random_pad_touches(rng, 40, 0.012, 0.045);
    Eigen::VectorXd got(2);
    c.distances(test, got);
    Index charged = 0;
    const Eigen::VectorXd want = formula_distances(c, objects, test, charged);
    CHECK(got(0) == want(0));
    CHECK(got(1) == want(1));
    CHECK(charged > 100);
  }
  // At the edge of the skipped heights: every taxel of a flat pad pressed
  // at 30.2 (30.1) mm, and a test whose free taxels lie right above them
  // at 32.3 (32.45) mm, 0.1 (0.35) voxels more than the free radius (2 mm)
  // above the felt surface. Their nearest lattice nodes are at 32 mm, 1.8
  // (1.9) mm above it, so they are charged, each where its node is close
  // enough to a pressed taxel: a point may be skipped only beyond free
  // radius + half a voxel.
  for (const auto& edge : std::vector<std::pair<double, double>>{{0.0302, 0.0323}, {0.0301, 0.03245}}) {
    const double felt = edge.first, z = edge.second;  // not a structured binding: CAPTURE's lambda captures z
    CAPTURE(z);
    const std::vector<TouchSet> flat = {pad_touches(Box{0.2, 0.2, felt}, {{0.0, 0.0}})};
    OccupancyClassifier c = one_placement(0);
    c.fit(flat, 0);
    const TouchSet test = pad_touches(Box{0.004, 0.004, z}, {{0.0, 0.0}});  // 2 x 2 taxels pressed
    REQUIRE(test.free_points.cols() == 80);
    Eigen::VectorXd got(1);
    c.distances(test, got);
    Index charged = 0;
    const Eigen::VectorXd want = formula_distances(c, flat, test, charged);
    CHECK(charged >= 10);
    CHECK(got(0) == want(0));
  }
}

/// One touch pressing straight down with the given contact points and one
/// free point.
static TouchSet one_touch(const Eigen::Matrix3Xd& contacts, const Eigen::Vector3d& free) {
  TouchSet t;
  t.positions = contacts.col(0);
  t.normals = Eigen::Vector3d(0, 0, -1);
  t.contact_points = contacts;
  t.contact_offsets = {0, contacts.cols()};
  t.free_points = free;
  t.free_offsets = {0, 1};
  return t;
}

TEST_CASE("occupancy: a free point is charged up to the edge of the skipped distances across, under a placement") {
  // The classifier also skips the free points too far across from the
  // object to be charged under any placement: beyond the occupied points'
  // radius about the turn centre + the largest shift + free radius + a
  // voxel, or farther from their bounding box than the largest shift +
  // the chord of the largest turn + free radius + a voxel. Each case
  // below puts a free point at the edge: under the placement that fits the
  // test's contact points best it lands 0.44 voxels beyond the free radius
  // from the nearest felt point, at a lattice node 1.95 mm from it, so it
  // is charged. The contradiction's charge:
  OccupancyClassifier c;
  const double z = 0.03, rho = c.free_radius;
  const double penalty = c.conflict_weight * static_cast<double>(static_cast<float>(c.truncation * c.truncation));
  const Eigen::Vector3d far(0, 0.2, z);  // a free point far from everything
  OccupancyEvidence felt;
  felt.turn_centre = Eigen::Vector2d::Zero();
  // The free point p lands at q under the best placement; its charge is
  // what it adds to the distance of the same touch with `far` instead,
  // which is returned.
  auto check_charged = [&](const Eigen::Matrix3Xd& contacts, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
    const TruncatedDistanceField field(felt.occupied, {c.voxel, c.truncation});
    REQUIRE(field.node_squared_distance(q) < static_cast<float>(rho * rho));
    REQUIRE((felt.occupied.colwise() - q).colwise().norm().minCoeff() > rho + 0.4 * c.voxel);
    Eigen::VectorXd charged(1), uncharged(1);
    c.distances(one_touch(contacts, p), charged);
    c.distances(one_touch(contacts, far), uncharged);
    CHECK(charged(0) == uncharged(0) + penalty);
    return uncharged(0);
  };
  SUBCASE("shifted: beyond the radius + shift + free radius") {
    // Felt: five points on the x axis out to 2.05 mm. The test's contact
    // points are those moved 4 mm along x, so the placement that shifts
    // it back by 4 mm fits best; p is 8.49 mm from the centre, beyond
    // radius + shift + free radius (8.05 mm) and beyond that + 0.3 voxels.
    felt.occupied.resize(3, 5);
    felt.occupied << -2.05e-3, -1e-3, 0, 1e-3, 2.05e-3, 0, 0, 0, 0, 0, z, z, z, z, z;
    c.placements.max_shift = 4e-3;
    c.placements.shift_step = 4e-3;
    c.placements.max_yaw = 0;
    c.fit_evidence({felt});
    REQUIRE(c.placement_count() == 5);
    Eigen::Matrix3Xd contacts = felt.occupied;
    contacts.row(0).array() += 4e-3;
    const Eigen::Vector3d p(8.49e-3, 0, z);
    REQUIRE(p.head<2>().norm() > 2.05e-3 + 4e-3 + rho + 0.3 * c.voxel);
    const double uncharged = check_charged(contacts, p, p - Eigen::Vector3d(4e-3, 0, 0));
    // One voxel farther out, p is skipped, and it could not have been charged.
    Eigen::VectorXd beyond(1);
    c.distances(one_touch(contacts, p + Eigen::Vector3d(c.voxel, 0, 0)), beyond);
    CHECK(beyond(0) == uncharged);
  }
  SUBCASE("turned: 11.8 mm across from the bounding box, which a 10 degree turn 65 mm out covers") {
    // Felt: five points along y = 10 mm, 58 to 62.05 mm out. The test is
    // those turned by -10 degrees about the centre, so the +10 degree
    // placement fits best. p, 65.3 mm out, is 11.8 mm from the felt
    // points' bounding box: beyond free radius + a voxel, within the
    // chord of 10 degrees at its distance (11.4 mm) + that.
    felt.occupied.resize(3, 5);
    felt.occupied << 58e-3, 59e-3, 60e-3, 61e-3, 62.05e-3, 10e-3, 10e-3, 10e-3, 10e-3, 10e-3, z, z, z, z, z;
    c.placements.max_shift = 0;
    c.placements.max_yaw = 10 * kPi / 180;
    c.placements.yaw_step = 10 * kPi / 180;
    c.fit_evidence({felt});
    REQUIRE(c.placement_count() == 3);
    const Eigen::Matrix3d back = Eigen::AngleAxisd(-10 * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d q(64.49e-3, 10e-3, z);
    const Eigen::Vector3d p = back * q;
    const Eigen::Vector2d gap(p.x() - 62.05e-3, 10e-3 - p.y());
    REQUIRE(gap.norm() > 0.0115);
    check_charged(back * felt.occupied, p, q);
  }
  SUBCASE("in place: 0.69 voxels beyond the free radius, diagonally across a lattice cell") {
    // Felt: one point 0.4 mm off the lattice on both axes across. p, 2.67
    // mm from it, is nearest the node at (1, 1) mm, 1.98 mm from it: within
    // the free radius. A node lies up to sqrt(2)/2 voxels across from a
    // point, more than the half voxel that bounds it along one axis.
    felt.occupied = Eigen::Vector3d(-0.4e-3, -0.4e-3, z);
    c.placements.max_shift = 0;
    c.placements.max_yaw = 0;
    c.fit_evidence({felt});
    const Eigen::Vector3d p(1.49e-3, 1.49e-3, z);
    check_charged(felt.occupied, p, p);
  }
}

TEST_CASE("occupancy: a test re-placed within the placement bounds is found, beyond them it is not") {
  OccupancyClassifier c;
  c.fit(training(), 0);
  OccupancyClassifier fixed;  // the identity placement only
  fixed.placements.max_shift = 0;
  fixed.placements.max_yaw = 0;
  fixed.fit(training(), 0);
  REQUIRE(fixed.placement_count() == 1);
  const TouchSet test = pad_touches(kLarge, {{0.04, 0.0}, {-0.035, 0.01}, {0.0, -0.02}, {0.02, 0.02}});
  Eigen::VectorXd d(2), e(2);
  fixed.distances(test, e);
  const double at_home = e(1);
  // The large box put down again: moved by the inverse of the grid's
  // placement (8 mm along x, 5 degrees about the references' centre, the
  // origin). The grid maps the touches back exactly, so the distance is at
  // most the one in place, up to rounding ...
  const TouchSet away = moved(moved(test, Eigen::Vector2d(-0.008, 0.0), 0), Eigen::Vector2d::Zero(), -5 * kPi / 180);
  c.distances(away, d);
  CHECK(d(1) <= at_home * (1 + 1e-6) + 1e-15);
  CHECK(d(1) < d(0));
  // ... while without the search it is far larger.
  fixed.distances(away, e);
  CHECK(e(1) > 2 * at_home);
  // 25 mm away is beyond the 10 mm prior: the contacts fall off the
  // references and the distance grows.
  Eigen::VectorXd far(2);
  c.distances(moved(test, Eigen::Vector2d(0.0, 0.025), 0), far);
  CHECK(far(1) > at_home + 1e-6);
  // Truncation bounds a touch's cost: each contact point at most tau^2 plus
  // one contradiction, each free point at most one contradiction.
  const double tau2 = c.truncation * c.truncation;
  const double bound = static_cast<double>(test.contact_points.cols()) * tau2 * (1 + c.conflict_weight) +
                       static_cast<double>(test.free_points.cols()) * tau2 * c.conflict_weight;
  CHECK(far(0) <= bound * (1 + 1e-6));
  CHECK(far(1) <= bound * (1 + 1e-6));
}

TEST_CASE("occupancy: a contact point where no training pad ever was costs unknown_cost (kappa) tau^2") {
  // A box 50 mm above the references' tops: its pressed taxels have no
  // evidence of either kind within reach, and its free points no occupied
  // point (so no contradiction), under the identity placement.
  const Box high{0.02, 0.02, 0.08};
  const TouchSet test = pad_touches(high, {{0.0, 0.0}, {0.005, 0.0}});
  const auto contacts = static_cast<double>(test.contact_points.cols());
  REQUIRE(contacts > 0);
  // On the small box's top, in place: every pressed taxel on the evidence.
  const TouchSet known = pad_touches(kSmall, {{0.0, 0.0}, {0.01, 0.005}});
  Eigen::VectorXd d(2), k1(2), k4(2);
  for (double u : {1.0, 0.4, 0.0}) {
    CAPTURE(u);
    OccupancyClassifier c;
    c.unknown_cost = u;
    c.placements.max_shift = 0;
    c.placements.max_yaw = 0;
    c.fit(training(), 0);
    c.distances(test, d);
    const double tau2 = c.truncation * c.truncation;
    CHECK(d(0) == doctest::Approx(contacts * u * tau2).epsilon(1e-5).scale(tau2));
    CHECK(d(1) == doctest::Approx(contacts * u * tau2).epsilon(1e-5).scale(tau2));
    if (u == 1.0) c.distances(known, k1);
    if (u == 0.4) c.distances(known, k4);
  }
  // Where the references saw the surface, the cost does not depend on it.
  CHECK(k4(0) == doctest::Approx(k1(0)).epsilon(1e-12));
  CHECK(k1(0) < 0.1 * static_cast<double>(known.contact_points.cols()) * 9e-6);
  // Bounds.
  OccupancyClassifier c;
  for (double bad : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    c.unknown_cost = bad;
    CHECK(error_of([&] { c.fit(training(), 0); }).find("unknown_cost: must be in [0, 1]") != std::string::npos);
  }
}

TEST_CASE("occupancy: placements turn about the given centre") {
  const std::vector<TouchSet> objects = training();
  std::vector<OccupancyEvidence> ev(2);
  for (std::size_t j = 0; j < 2; ++j) {
    ev[j].occupied = objects[j].contact_points;
    ev[j].free = objects[j].free_points;
  }
  // The large box's turn axis at its corner (0.05, 0.03) instead of its centre.
  ev[1].turn_centre = Eigen::Vector2d(0.05, 0.03);
  OccupancyClassifier fixed, c;
  fixed.placements.max_shift = 0;
  fixed.placements.max_yaw = 0;
  fixed.fit_evidence(ev);
  c.fit_evidence(ev);
  const TouchSet test = pad_touches(kLarge, {{0.04, 0.0}, {-0.035, 0.01}, {0.0, -0.02}, {0.02, 0.02}});
  Eigen::VectorXd d(2), e(2);
  fixed.distances(test, e);
  // Turned by -10 degrees about that corner: the grid's 10 degree turn about
  // it brings the touches back exactly.
  const Eigen::Vector2d corner(0.05, 0.03);
  const TouchSet turned =
      moved(moved(moved(test, -corner, 0), Eigen::Vector2d::Zero(), -10 * kPi / 180), corner, 0);
  c.distances(turned, d);
  CHECK(d(1) <= e(1) * (1 + 1e-6) + 1e-15);
  fixed.distances(turned, e);
  CHECK(e(1) > 2 * d(1));
  ev[0].turn_centre = Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 0);
  CHECK(error_of([&] { c.fit_evidence(ev); }).find("objects[0].turn_centre") != std::string::npos);
}

TEST_CASE("occupancy: pool distances equal the distances of the subset, bit for bit") {
  OccupancyClassifier c;
  c.fit(training(), 0);
  Rng rng(3);
  std::vector<Eigen::Vector2d> centres;
  for (int i = 0; i < 12; ++i) centres.emplace_back(rng.uniform(-0.05, 0.05), rng.uniform(-0.03, 0.03));
  const TouchSet pool = pad_touches(kLarge, centres);
  const auto prepared = c.prepare_pool(pool);
  REQUIRE(prepared);
  for (const std::vector<Index>& subset : {std::vector<Index>{3}, std::vector<Index>{0, 5, 2, 11},
                                           std::vector<Index>{11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0}}) {
    Eigen::VectorXd a(2), b(2), e(2);
    c.pool_distances(pool, prepared.get(), subset, a);
    c.distances(select_touches(pool, subset), b);
    c.pool_distances(pool, nullptr, subset, e);
    CHECK(a == b);
    CHECK(e == b);
  }
  // A preparation is tied to its classifier's fit and pool.
  Eigen::VectorXd d(2);
  CHECK(error_of([&] { c.pool_distances(select_touches(pool, std::vector<Index>{0, 1}), prepared.get(), {0}, d); })
            .find("prepared") != std::string::npos);
  OccupancyClassifier other;
  other.fit(training(), 0);
  CHECK(error_of([&] { other.pool_distances(pool, prepared.get(), {0}, d); }).find("prepared") != std::string::npos);
  CHECK(error_of([&] { c.pool_distances(pool, prepared.get(), {12}, d); }).find("subset") != std::string::npos);
  // Another pool of the same size (here the same pads on the small box) is
  // not scored with this one's costs.
  const TouchSet same_size = pad_touches(kSmall, centres);
  REQUIRE(same_size.size() == pool.size());
  CHECK(error_of([&] { c.pool_distances(same_size, prepared.get(), {0}, d); }).find("prepared") != std::string::npos);
  // A drawn touch's free or contact points moved by a bit: refused; the
  // offsets of another pool pointing past its points: refused as a corrupt
  // pool (TouchSet::validate_layout) before the preparation is compared,
  // nothing read outside it (AddressSanitizer checks the reads in CI).
  TouchSet moved_free = pool;
  REQUIRE(moved_free.free_of(4) > 0);
  double& x = moved_free.free_points(0, moved_free.free_offsets[4]);
  x = std::nextafter(x, 1.0);
  CHECK(error_of([&] { c.pool_distances(moved_free, prepared.get(), {4}, d); }).find("prepared") != std::string::npos);
  CHECK(error_of([&] { c.pool_distances(moved_free, prepared.get(), {3, 5}, d); }).empty());
  TouchSet moved_contact = pool;
  REQUIRE(moved_contact.contacts_of(2) > 0);
  moved_contact.contact_points(2, moved_contact.contact_offsets[2]) += 1e-3;
  CHECK(error_of([&] { c.pool_distances(moved_contact, prepared.get(), {2}, d); }).find("prepared") != std::string::npos);
  TouchSet corrupt = pool;
  corrupt.free_offsets[7] = corrupt.free_points.cols() + 100;
  CHECK(error_of([&] { c.pool_distances(corrupt, prepared.get(), {6}, d); }).find("pool.free_offsets: must rise") !=
        std::string::npos);
  c.fit(training(), 0);
  CHECK(error_of([&] { c.pool_distances(pool, prepared.get(), {0}, d); }).find("prepared") != std::string::npos);
}

TEST_CASE("occupancy: CAD-like evidence (surface samples, no free points) recognises a touched box") {
  // References sampled on each top face, as from a model: no free evidence.
  std::vector<OccupancyEvidence> ev(2);
  for (int b = 0; b < 2; ++b) {
    const Box& box = b == 0 ? kSmall : kLarge;
    std::vector<Eigen::Vector3d> pts;
    for (double x = -box.length / 2; x <= box.length / 2 + 1e-12; x += 5e-4)
      for (double y = -box.width / 2; y <= box.width / 2 + 1e-12; y += 5e-4) pts.emplace_back(x, y, box.height);
    ev[static_cast<std::size_t>(b)].occupied.resize(3, static_cast<Index>(pts.size()));
    for (std::size_t k = 0; k < pts.size(); ++k) ev[static_cast<std::size_t>(b)].occupied.col(static_cast<Index>(k)) = pts[k];
  }
  OccupancyClassifier c;
  c.fit_evidence(ev);
  Eigen::VectorXd d(2);
  // A pad overhanging the small box's edge: its free taxels lie over the
  // large box's top, a contradiction only for the large box.
  c.distances(pad_touches(kSmall, {{0.03, 0.0}, {0.0, 0.02}}), d);
  CHECK(d(0) < d(1));
  c.distances(pad_touches(kLarge, {{0.045, 0.0}, {-0.04, 0.02}}), d);
  CHECK(d(1) < d(0));
}

TEST_CASE("occupancy: bad settings, missing taxels and misuse are refused, naming them") {
  OccupancyClassifier c;
  Eigen::VectorXd d(2);
  const TouchSet t = pad_touches(kSmall, {{0.0, 0.0}});
  CHECK(error_of([&] { c.distances(t, d); }).find("distances: called before fit") != std::string::npos);
  CHECK(error_of([&] { c.prepare_pool(t); }).find("prepare_pool: called before fit") != std::string::npos);
  c.free_radius = 4e-3;  // above the truncation
  CHECK(error_of([&] { c.fit(training(), 0); }).find("free_radius") != std::string::npos);
  c = OccupancyClassifier{};
  c.conflict_weight = -1;
  CHECK(error_of([&] { c.fit(training(), 0); }).find("conflict_weight") != std::string::npos);
  c = OccupancyClassifier{};
  c.truncation = 0.1;  // 100 voxels
  CHECK(error_of([&] { c.fit(training(), 0); }).find("truncation: must be > 0 and at most 64 voxels") == 0);
  // Named by the classifier's members (the field's "settings.voxel" and
  // "settings.truncation" are not its settings), and a free_radius the
  // free points' field refuses is refused by validate() already, as itself
  // (fit named it "settings.truncation").
  c = OccupancyClassifier{};
  c.voxel = 0;
  CHECK(error_of([&] { c.validate(); }).find("voxel: must be finite and > 0") == 0);
  c = OccupancyClassifier{};
  c.free_radius = 1e-20;
  CHECK(error_of([&] { c.validate(); }).find("free_radius: must square to a normal finite float") == 0);
  c = OccupancyClassifier{};
  c.placements.yaw_step = 0;
  CHECK(error_of([&] { c.fit(training(), 0); }).find("placements.yaw_step") != std::string::npos);
  c = OccupancyClassifier{};
  CHECK(error_of([&] { c.fit({}, 0); }).find("objects") != std::string::npos);
  std::vector<TouchSet> objects = training();
  objects[1].free_offsets.clear();
  objects[1].free_points.resize(3, 0);
  CHECK(error_of([&] { c.fit(objects, 0); }).find("objects[1].free_points") != std::string::npos);
  objects = training();
  objects[0].contact_offsets.clear();
  objects[0].contact_points.resize(3, 0);
  CHECK(error_of([&] { c.fit(objects, 0); }).find("objects[0].contact_points") != std::string::npos);
  CHECK(error_of([&] { c.fit_evidence({OccupancyEvidence{}}); }).find("objects[0].occupied") != std::string::npos);
  c.fit(training(), 0);
  TouchSet bare = t;
  bare.free_offsets.clear();
  bare.free_points.resize(3, 0);
  CHECK(error_of([&] { c.distances(bare, d); }).find("test.free_points") != std::string::npos);
  CHECK(error_of([&] { c.prepare_pool(bare); }).find("pool.free_points") != std::string::npos);
  Eigen::VectorXd wrong(3);
  CHECK(error_of([&] { c.distances(t, wrong); }).find("out") != std::string::npos);
  // The settings of the last fit hold until the next one.
  c.distances(t, d);
  const Eigen::VectorXd before = d;
  c.conflict_weight = 5;
  c.distances(t, d);
  CHECK(d == before);
}

TEST_CASE("occupancy: settings at and past their bounds, the label, and invalid touches, each named") {
  // The placements: a negative shift or turn bound is refused, not read
  // as an empty grid.
  PlanarPlacements p;
  p.max_shift = -1e-3;
  CHECK(error_of([&] { p.validate("p"); }).find("p.max_shift: must be finite and >= 0") == 0);
  p = PlanarPlacements{};
  p.max_yaw = -0.1;
  CHECK(error_of([&] { p.validate("p"); }).find("p.max_yaw: must be in [0, pi] rad") == 0);
  // The classifier's validate() checks its placements too (fit refuses
  // nothing validate() accepted), and so does back_layers().
  OccupancyClassifier c;
  c.placements.yaw_step = 0;
  CHECK(error_of([&] { c.validate(); }).find("placements.yaw_step") == 0);
  CHECK(error_of([&] { c.back_layers(); }).find("placements.yaw_step") == 0);
  // A free radius equal to the truncation is allowed.
  c = OccupancyClassifier{};
  c.free_radius = c.truncation;
  CHECK_NOTHROW(c.validate());
  c.fit(training(), 0);
  CHECK(c.objects() == 2);
  // Its name in a Recognizer, and in its errors.
  CHECK(c.name() == "occupancy");
  c.label = "occupancy_far";
  CHECK(c.name() == "occupancy_far");
  TouchSet bare = pad_touches(kSmall, {{0.0, 0.0}});
  bare.free_offsets.clear();
  bare.free_points.resize(3, 0);
  Eigen::VectorXd d(2);
  CHECK(error_of([&] { c.distances(bare, d); }).find("the occupancy_far classifier needs") != std::string::npos);
  // m = ceil(b / (1.5 rho)) layers for a depth of exactly m steps, also
  // where the division rounds up: 0.03375 / (1.5 * 0.0025) is
  // 9.000000000000002 in doubles, and takes 9 layers, not 10.
  c.free_radius = 0.0025;
  c.back_depth = 0.03375;
  const std::vector<double> layers = c.back_layers();
  REQUIRE(layers.size() == 9);
  CHECK(layers[0] == doctest::Approx(0.00375).epsilon(1e-12));
  CHECK(layers[8] == 0.03375);
  // fit checks the training touches first, naming what the caller gave.
  std::vector<TouchSet> objects = training();
  objects[1].contact_points(2, 5) = std::numeric_limits<double>::quiet_NaN();
  c = OccupancyClassifier{};
  CHECK_THROWS_AS(c.fit(objects, 0), NonFiniteValue);
  CHECK(error_of([&] { c.fit(objects, 0); }).find("objects[1].contact_points") == 0);
  // So do distances and prepare_pool with a test's and a pool's touches.
  c.fit(training(), 0);
  TouchSet nan_test = pad_touches(kSmall, {{0.0, 0.0}});
  nan_test.contact_points(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK(error_of([&] { c.distances(nan_test, d); }).find("test.contact_points") == 0);
  CHECK(error_of([&] { c.prepare_pool(nan_test); }).find("pool.contact_points") == 0);
}

TEST_CASE("occupancy: distances keep the last fit's conflict_weight and unknown_cost") {
  OccupancyClassifier c = one_placement(0);
  c.unknown_cost = 0.4;
  c.fit(training(), 0);
  // Contradictions decide this test (the first case above), and these
  // touches, 50 mm above the references, are charged kappa tau^2.
  const TouchSet contradicted = pad_touches(kSmall, {{0.02, 0.0}, {-0.02, 0.0}, {0.0, 0.0}});
  const TouchSet unknown = pad_touches(Box{0.02, 0.02, 0.08}, {{0.0, 0.0}});
  Eigen::VectorXd a(2), b(2), a_after(2), b_after(2);
  c.distances(contradicted, a);
  c.distances(unknown, b);
  REQUIRE(a(0) < a(1));
  const double tau2 = static_cast<double>(static_cast<float>(c.truncation * c.truncation));
  REQUIRE(b(0) == doctest::Approx(static_cast<double>(unknown.contact_points.cols()) * 0.4 * tau2).epsilon(1e-6).scale(0));
  c.conflict_weight = 5;
  c.unknown_cost = 1;
  c.distances(contradicted, a_after);
  c.distances(unknown, b_after);
  CHECK(a_after == a);
  CHECK(b_after == b);
}

TEST_CASE("occupancy: a contact point's cost at the edges of the formula") {
  // Felt at the origin; a pad felt nothing 2 mm along x (the free radius);
  // both on lattice nodes. Identity placement, kappa 0.4.
  OccupancyEvidence felt;
  felt.occupied = Eigen::Vector3d::Zero();
  felt.free = Eigen::Vector3d(2e-3, 0, 0);
  OccupancyClassifier c = one_placement(0);
  c.unknown_cost = 0.4;
  const double tau2 = static_cast<double>(static_cast<float>(c.truncation * c.truncation));
  const Eigen::Vector3d far(0, 0.2, 0);  // a free point far from everything
  Eigen::VectorXd d(1);
  auto cost = [&](double x) {
    c.distances(one_touch(Eigen::Vector3d(x, 0, 0), far), d);
    return d(0);
  };
  for (const double gamma : {0.3, 0.0}) {
    CAPTURE(gamma);
    c.conflict_weight = gamma;
    c.fit_evidence({felt});
    // 1 mm from both kinds: D_free = D_occ is no contradiction (it needs
    // D_free < min(D_occ, rho)).
    CHECK(cost(1e-3) == static_cast<double>(static_cast<float>(1e-6)));
    // 3.5 mm out: beyond the felt point's truncation, but 1.5 mm from
    // where a pad felt nothing: a miss and a contradiction, not unknown.
    CHECK(cost(3.5e-3) == doctest::Approx((1 + gamma) * tau2).epsilon(1e-6).scale(0));
    // 6 mm out: no evidence of either kind within reach: kappa tau^2, with
    // or without the contradictions.
    CHECK(cost(6e-3) == doctest::Approx(0.4 * tau2).epsilon(1e-6).scale(0));
  }
}

TEST_CASE("occupancy: pool_distances refuses an empty subset and a wrong output size, as distances does") {
  OccupancyClassifier c;
  c.fit(training(), 0);
  const TouchSet pool = pad_touches(kLarge, {{0.0, 0.0}, {0.02, 0.01}});
  const auto prepared = c.prepare_pool(pool);
  Eigen::VectorXd d(2), wrong(3);
  for (const PreparedPool* p : {prepared.get(), static_cast<const PreparedPool*>(nullptr)}) {
    CAPTURE(p != nullptr);
    CHECK_THROWS_AS(c.pool_distances(pool, p, {}, d), EmptyInput);
    CHECK(error_of([&] { c.pool_distances(pool, p, {}, d); }).find("test: holds no touch") == 0);
    CHECK_THROWS_AS(c.pool_distances(pool, p, {0, 1}, wrong), DimensionMismatch);
    CHECK(error_of([&] { c.pool_distances(pool, p, {0, 1}, wrong); }).find("out") == 0);
  }
}

TEST_CASE("occupancy: without a turn_centre, placements turn about the centroid of the occupied points") {
  // Both boxes' training touches 0.2 m along x and 0.1 m along y from the
  // origin, fitted from touches (no turn_centre).
  const Eigen::Vector2d at(0.2, 0.1);
  std::vector<TouchSet> objects = training();
  for (TouchSet& o : objects) o = moved(o, at, 0);
  OccupancyClassifier c, fixed = one_placement(0);
  c.fit(objects, 0);
  fixed.fit(objects, 0);
  const TouchSet test = moved(pad_touches(kLarge, {{0.04, 0.0}, {-0.035, 0.01}, {0.0, -0.02}, {0.02, 0.02}}), at, 0);
  Eigen::VectorXd d(2), e(2);
  fixed.distances(test, e);
  // Turned by -10 degrees about the large box's contact centroid: the grid's
  // 10 degree turn about it brings the touches back exactly. (About the
  // origin, 0.22 m away, that turn would move them by 39 mm.)
  const Eigen::Vector2d centroid = objects[1].contact_points.topRows<2>().rowwise().mean();
  const TouchSet turned = moved(moved(moved(test, -centroid, 0), Eigen::Vector2d::Zero(), -10 * kPi / 180), centroid, 0);
  c.distances(turned, d);
  CHECK(d(1) <= e(1) * (1 + 1e-6) + 1e-15);
  fixed.distances(turned, e);
  CHECK(e(1) > 2 * d(1));
}
