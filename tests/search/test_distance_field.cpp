// SPDX-License-Identifier: MIT
// TruncatedDistanceField against brute force: exact at the nodes, within
// the interpolation bound between them, truncated far away; its errors.
#include <doctest/doctest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "iclap/core/random.hpp"
#include "iclap/search/distance_field.hpp"
#include "../support/errors.hpp"

using namespace iclap;

namespace {

/// min(min_p |q - p|^2, tau^2) by brute force.
double exact(const Eigen::Matrix3Xd& points, const Eigen::Vector3d& q, double tau) {
  double best = tau * tau;
  for (Index c = 0; c < points.cols(); ++c) best = std::min(best, (points.col(c) - q).squaredNorm());
  return best;
}

/// Random points in a box that straddles the origin, so that negative
/// lattice indices and block boundaries on both sides are exercised.
Eigen::Matrix3Xd random_points(Rng& rng, Index n, double half) {
  Eigen::Matrix3Xd p(3, n);
  for (Index c = 0; c < n; ++c)
    for (Index r = 0; r < 3; ++r) p(r, c) = rng.uniform(-half, half);
  return p;
}

/// The what() of the InvalidArgument building a field of `pts` with `s`
/// throws, the points named "evidence"; "(no error)" when the field is built.
std::string refusal(const Eigen::Matrix3Xd& pts, const DistanceFieldSettings& s) {
  return test::what_of([&] { TruncatedDistanceField f(pts, s, "evidence"); });
}

}  // namespace

TEST_CASE("distance field: exact at the lattice nodes, truncated beyond reach") {
  Rng rng(7);
  const Eigen::Matrix3Xd pts = random_points(rng, 60, 0.02);
  const DistanceFieldSettings s{1e-3, 3e-3};
  const TruncatedDistanceField f(pts, s);
  CHECK(f.cap() == static_cast<float>(9e-6));
  int checked = 0, inside = 0;
  for (int i = -26; i <= 26; i += 1)
    for (int j = -26; j <= 26; j += 3)
      for (int k = -26; k <= 26; k += 2) {
        const Eigen::Vector3d q = 1e-3 * Eigen::Vector3d(i, j, k);
        const double e = exact(pts, q, 3e-3);
        // At a node the stored value is the exact one (rounded to float).
        CHECK(f.squared_distance(q) == doctest::Approx(e).epsilon(1e-6).scale(1e-12));
        ++checked;
        if (e < 9e-6) ++inside;
      }
  CHECK(checked > 10000);
  CHECK(inside > 1000);  // the test saw both kinds of node
}

TEST_CASE("distance field: between nodes within the trilinear bound of the exact value") {
  Rng rng(11);
  const double h = 1e-3, tau = 3e-3;
  const Eigen::Matrix3Xd pts = random_points(rng, 40, 0.015);
  const TruncatedDistanceField f(pts, {h, tau});
  double worst_over = 0;
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Vector3d q(rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02));
    const double e = exact(pts, q, tau);
    const double v = f.squared_distance(q);
    // The interpolant of the closest point's |x - p|^2 exceeds it by at
    // most 3/4 h^2, and the field is the interpolant of a minimum, so it is
    // never above that bound (nor above the cap) ...
    CHECK(v <= std::min(e + 0.75 * h * h, tau * tau) * (1 + 1e-6) + 1e-15);
    worst_over = std::max(worst_over, v - e);
    // ... and never negative.
    CHECK(v >= 0);
  }
  CHECK(worst_over > 0.1 * h * h);  // the bound was approached, not vacuous
  // The nearest-node read gives the exact value at the closest node.
  for (int n = 0; n < 2000; ++n) {
    const Eigen::Vector3d q(rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02));
    const Eigen::Vector3d node = h * (q / h).array().round().matrix();
    CHECK(f.node_squared_distance(q) == doctest::Approx(exact(pts, node, tau)).epsilon(1e-6).scale(1e-12));
  }
  // On a point itself the value is the interpolation error alone.
  for (Index c = 0; c < pts.cols(); ++c) CHECK(f.squared_distance(pts.col(c)) <= 0.75 * h * h * (1 + 1e-6));
}

TEST_CASE("distance field: far queries, NaN queries and no points give the cap") {
  const Eigen::Matrix3Xd one = Eigen::Vector3d(0.1, -0.2, 0.05);
  const TruncatedDistanceField f(one, {1e-3, 2e-3});
  CHECK(f.squared_distance(Eigen::Vector3d(0.1, -0.2, 0.05)) == 0.0f);  // a node
  CHECK(f.squared_distance(Eigen::Vector3d(0.1, -0.2, 0.0521)) == f.cap());
  CHECK(f.squared_distance(Eigen::Vector3d(5, 5, 5)) == f.cap());
  CHECK(f.squared_distance(Eigen::Vector3d(-1e30, 0, 0)) == f.cap());
  CHECK(f.squared_distance(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN())) == f.cap());
  CHECK(f.node_squared_distance(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN())) == f.cap());
  CHECK(f.node_squared_distance(Eigen::Vector3d(-1e30, 0, 0)) == f.cap());
  CHECK(f.node_squared_distance(Eigen::Vector3d(0.1004, -0.2003, 0.0502)) == 0.0f);
  const TruncatedDistanceField none(Eigen::Matrix3Xd(3, 0), {1e-3, 2e-3});
  CHECK(none.cap() == static_cast<float>(4e-6));
  CHECK(none.squared_distance(Eigen::Vector3d::Zero()) == none.cap());
  CHECK(none.node_squared_distance(Eigen::Vector3d::Zero()) == none.cap());
  CHECK(none.memory_bytes() == 0);
  const TruncatedDistanceField empty;
  CHECK(empty.squared_distance(Eigen::Vector3d::Zero()) == 0.0f);
}

TEST_CASE("distance field: memory follows the points' surface, not their bounding box") {
  // A 30 cm square sheet at 1 mm voxels: the box is 0.3 x 0.3 x 0.01 m, the
  // blocks only those within 3 mm of the sheet.
  Eigen::Matrix3Xd sheet(3, 301 * 301);
  for (int i = 0; i <= 300; ++i)
    for (int j = 0; j <= 300; ++j) sheet.col(i * 301 + j) = Eigen::Vector3d(i * 1e-3, j * 1e-3, 0.0);
  const TruncatedDistanceField f(sheet, {1e-3, 3e-3});
  // Dense nodes over the box would be 301 x 301 x 7 floats; the blocks
  // holding the band are at most two layers of 8 nodes thick.
  CHECK(f.memory_bytes() < std::size_t{40 * 40 * 2 * 512 * 4 + 40 * 40 * 3 * 4});
  CHECK(f.squared_distance(Eigen::Vector3d(0.15, 0.15, 0.002)) == doctest::Approx(4e-6).epsilon(1e-5));
}

TEST_CASE("distance field: settings and points out of range are refused, naming them") {
  const Eigen::Matrix3Xd p = Eigen::Vector3d(0, 0, 0);
  CHECK(refusal(p, {0.0, 3e-3}).find("settings.voxel") != std::string::npos);
  CHECK(refusal(p, {std::numeric_limits<double>::quiet_NaN(), 3e-3}).find("settings.voxel") != std::string::npos);
  CHECK(refusal(p, {1e-3, 0.0}).find("settings.truncation") != std::string::npos);
  CHECK(refusal(p, {1e-3, 0.0641}).find("at most 64 voxels") != std::string::npos);
  CHECK(refusal(p, {1e-3, 0.064}) == "(no error)");
  // A truncation whose float square is 0 (every query read 0, as if at a
  // point) or inf; the extremes that square to normal floats are kept.
  CHECK(refusal(p, {1e-24, 3e-24}).find("settings.truncation: must square to a normal finite float") == 0);
  CHECK(refusal(p, {1e18, 3e19}).find("settings.truncation: must square to a normal finite float") == 0);
  const TruncatedDistanceField tiny(p, {1e-19, 2e-19});
  CHECK(tiny.cap() > 0);
  CHECK(tiny.squared_distance(Eigen::Vector3d(1e-15, 0, 0)) == tiny.cap());
  const TruncatedDistanceField huge(p, {1e18, 1e19});
  CHECK(std::isfinite(huge.cap()));
  Eigen::Matrix3Xd bad = p;
  bad(1, 0) = std::numeric_limits<double>::infinity();
  CHECK(refusal(bad, {}).find("evidence") != std::string::npos);
  Eigen::Matrix3Xd far = p;
  far(2, 0) = 2e5;  // millimetres taken for metres
  const std::string m = refusal(far, {});
  CHECK(m.find("evidence") != std::string::npos);
  CHECK(m.find("beyond the field's range") != std::string::npos);
  // Two points 5 km apart would need an index of 10^13 blocks.
  Eigen::Matrix3Xd spread(3, 2);
  spread << 0, 5000, 0, 5000, 0, 5000;
  CHECK(refusal(spread, {}).find("use a larger voxel") != std::string::npos);
  CHECK(refusal(spread, {100.0, 200.0}) == "(no error)");
}

TEST_CASE("distance field: an infinite voxel, a zero truncation and one squaring to a subnormal float are refused") {
  const Eigen::Matrix3Xd p = Eigen::Vector3d(0, 0, 0);
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(refusal(p, {inf, 3e-3}).find("settings.voxel: must be finite and > 0") == 0);
  CHECK(refusal(p, {1e-3, 0.0}).find("settings.truncation: must be > 0 and at most 64 voxels") == 0);
  // 1e-20 m squares to 1e-40, a subnormal float (below 1.18e-38).
  CHECK(refusal(p, {1e-21, 1e-20}).find("settings.truncation: must square to a normal finite float") == 0);
}

TEST_CASE("distance field: a coordinate of exactly kMaxCoordinateVoxels voxels is in range, the next double is not") {
  const DistanceFieldSettings s{1e-3, 3e-3};
  const double limit = TruncatedDistanceField::kMaxCoordinateVoxels * s.voxel;
  const Eigen::Matrix3Xd edge = Eigen::Vector3d(limit, -limit, 0);
  const TruncatedDistanceField f(edge, s, "evidence");
  CHECK(f.squared_distance(edge.col(0)) < f.cap());  // a field there, not only no error
  Eigen::Matrix3Xd beyond = edge;
  beyond(0, 0) = std::nextafter(limit, std::numeric_limits<double>::infinity());
  CHECK(refusal(beyond, s).find("beyond the field's range") != std::string::npos);
}

TEST_CASE("distance field: memory_bytes counts the dense block index as well as the blocks") {
  // Two points 0.8 m apart along each axis at 1 mm voxels: the index covers
  // at least 100 blocks of 8 voxels per axis, 4 bytes each, whereas the
  // blocks near the two points are a few tens of kilobytes.
  Eigen::Matrix3Xd two(3, 2);
  two << 0, 0.8, 0, 0.8, 0, 0.8;
  const TruncatedDistanceField f(two, {1e-3, 3e-3});
  CHECK(f.memory_bytes() >= std::size_t{100 * 100 * 100} * sizeof(std::int32_t));
}

TEST_CASE("distance field: queries up to the far corner of the indexed box read the cap") {
  // A point at the origin: with 8-node blocks the index spans nodes -8 to 7
  // on each axis, so the diagonal below crosses the last cell, whose far
  // corner lies outside the index (with the x bound of that lookup dropped,
  // it was read one entry past the index: a wrong value, or an
  // AddressSanitizer report).
  const Eigen::Matrix3Xd origin = Eigen::Vector3d(0, 0, 0);
  const TruncatedDistanceField f(origin, {1e-3, 3e-3});
  for (int t = 14; t <= 48; ++t) {
    const Eigen::Vector3d q = Eigen::Vector3d::Constant(t * 0.25e-3);  // 3.5 to 12 mm, beyond the truncation
    CAPTURE(t);
    CHECK(f.squared_distance(q) == f.cap());
    CHECK(f.node_squared_distance(q) == f.cap());
  }
}
