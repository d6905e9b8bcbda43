// SPDX-License-Identifier: MIT
// Point clouds of the user's own types (PointCloudTraits): read into the
// library's layout exactly, registered exactly as a matrix of the same
// values, and refused with errors that name the argument, the point and the
// coordinate.

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/point_cloud.hpp"
#include "iclap/registration/registration.hpp"
#include "../support/errors.hpp"

using iclap::test::argument_of;
using iclap::test::what_of;

namespace {

// A user's touch record: where (float, as a rig driver might give it) and
// which word.
struct Touch {
  Eigen::Vector3f position;
  int word;
};
using Touches = std::vector<Touch>;

// A user's cloud of run-time dimension: rows of doubles.
struct Rows {
  std::vector<std::vector<double>> rows;
  Eigen::Index dim;
};

// A container that reports whatever size and dimension it is given (a
// user's traits gone wrong), every coordinate 0.
struct Claimed {
  Eigen::Index size, dim;
};

}  // namespace

template <>
struct iclap::PointCloudTraits<Touches> {
  static iclap::Index size(const Touches& c) { return static_cast<iclap::Index>(c.size()); }
  static iclap::Index dimension(const Touches&) { return 4; }
  static double coordinate(const Touches& c, iclap::Index i, iclap::Index k) {
    const Touch& t = c[static_cast<std::size_t>(i)];
    return k < 3 ? static_cast<double>(t.position(k)) : static_cast<double>(t.word);
  }
};

template <>
struct iclap::PointCloudTraits<Rows> {
  static iclap::Index size(const Rows& c) { return static_cast<iclap::Index>(c.rows.size()); }
  static iclap::Index dimension(const Rows& c) { return c.dim; }
  static double coordinate(const Rows& c, iclap::Index i, iclap::Index k) {
    return c.rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
  }
};

template <>
struct iclap::PointCloudTraits<Claimed> {
  static iclap::Index size(const Claimed& c) { return c.size; }
  static iclap::Index dimension(const Claimed& c) { return c.dim; }
  static double coordinate(const Claimed&, iclap::Index, iclap::Index) { return 0; }
};

namespace {

// Twenty touches of an object, and the same touches after a planar motion.
Touches model_touches() {
  Touches t;
  for (int i = 0; i < 20; ++i)
    t.push_back({Eigen::Vector3f(0.01f * static_cast<float>(i), 0.004f * static_cast<float>(i % 5),
                                 0.002f * static_cast<float>(i % 3) + 0.001f * static_cast<float>(i % 2)),
                 i % 4});
  return t;
}

Touches moved(const Touches& in, float angle, const Eigen::Vector2f& shift) {
  Touches out = in;
  const Eigen::Rotation2Df R(angle);
  for (auto& t : out) t.position.head<2>() = R * t.position.head<2>() + shift;
  return out;
}

// The same values as a matrix, the library's own layout.
Eigen::Matrix4Xd as_matrix(const Touches& t) {
  Eigen::Matrix4Xd m(4, static_cast<Eigen::Index>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i)
    m.col(static_cast<Eigen::Index>(i)) << t[i].position.cast<double>(), static_cast<double>(t[i].word);
  return m;
}

}  // namespace

TEST_CASE("the traits tell point clouds from other types") {
  CHECK(iclap::is_point_cloud_v<Touches>);
  CHECK(iclap::is_point_cloud_v<const Touches&>);
  CHECK(iclap::is_point_cloud_v<Rows>);
  CHECK(iclap::is_point_cloud_v<std::vector<Eigen::Vector3d>>);
  CHECK(iclap::is_point_cloud_v<std::vector<Eigen::VectorXf>>);
  CHECK(iclap::is_point_cloud_v<std::vector<std::array<float, 2>>>);
  // Eigen types are taken as they are; others have no traits.
  CHECK_FALSE(iclap::is_point_cloud_v<Eigen::Matrix3Xd>);
  CHECK_FALSE(iclap::is_point_cloud_v<int>);
  CHECK_FALSE(iclap::is_point_cloud_v<std::vector<int>>);
  CHECK_FALSE(iclap::is_point_cloud_v<std::vector<std::array<std::string, 2>>>);
}

TEST_CASE("to_cloud reads every coordinate of every point, once, into a column") {
  const Touches t = model_touches();
  CHECK(iclap::traits::size(t) == 20);
  CHECK(iclap::traits::dimension(t) == 4);
  CHECK(iclap::traits::coordinate(t, 7, 3) == 3.0);
  const Eigen::Matrix4Xd expected = as_matrix(t);
  CHECK(iclap::to_cloud<double, 4>(t) == expected);
  CHECK(iclap::to_cloud<double>(t) == Eigen::MatrixXd(expected));  // Eigen::Dynamic rows
  CHECK(iclap::to_cloud<float, 4>(t) == expected.cast<float>());

  const std::vector<Eigen::Vector3d> v{{1, 2, 3}, {4, 5, 6}};
  Eigen::Matrix3Xd m(3, 2);
  m << 1, 4, 2, 5, 3, 6;
  CHECK(iclap::to_cloud<double, 3>(v) == m);
  const std::vector<std::array<float, 2>> a{{0.5f, -1.0f}, {2.0f, 3.0f}, {4.0f, 0.25f}};
  const Eigen::Matrix2Xf c = iclap::to_cloud<float, 2>(a);
  CHECK(c.cols() == 3);
  CHECK(c(0, 2) == 4.0f);
  CHECK(c(1, 0) == -1.0f);
  // An empty cloud is a matrix without columns; the callee decides.
  CHECK(iclap::to_cloud<double, 3>(std::vector<Eigen::Vector3d>{}).cols() == 0);
}

TEST_CASE("bad clouds are refused, naming the argument, the point and the coordinate") {
  Touches t = model_touches();
  try {
    iclap::to_cloud<double, 3>(t, "test");
    FAIL("a 4-D cloud was read as 3-D");
  } catch (const iclap::DimensionMismatch& e) {
    CHECK(e.argument() == "test");
    CHECK(e.expected() == 3);
    CHECK(e.actual() == 4);
  }
  t[5].position.y() = std::numeric_limits<float>::quiet_NaN();
  try {
    iclap::to_cloud<double, 4>(t, "points");
    FAIL("a NaN coordinate was read");
  } catch (const iclap::NonFiniteValue& e) {
    CHECK(e.argument() == "points");
    CHECK(e.row() == 1);
    CHECK(e.column() == 5);
  }
  // Finite in double, beyond float.
  const Rows big{{{0, 0}, {1e39, 0}}, 2};
  CHECK(iclap::to_cloud<double, 2>(big)(0, 1) == 1e39);
  try {
    iclap::to_cloud<float, 2>(big, "points");
    FAIL("1e39 was read into float");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "points");
    CHECK(std::string(e.what()).find("coordinate 0 of point 1 is 1e+39, beyond the range of float") !=
          std::string::npos);
  }
  // Points of different sizes in a run-time-sized vector: the point is named.
  const std::vector<Eigen::VectorXd> ragged{Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6), Eigen::Vector2d(7, 8)};
  try {
    iclap::to_cloud<double>(ragged, "points");
    FAIL("a ragged cloud was read");
  } catch (const iclap::DimensionMismatch& e) {
    CHECK(e.argument() == "points[2]");
    CHECK(e.expected() == 3);
    CHECK(e.actual() == 2);
  }
  const Rows negative{{}, -1};
  CHECK_THROWS_WITH_AS(iclap::to_cloud<double>(negative, "points"), doctest::Contains("negative dimension"),
                       iclap::InvalidArgument);
  // A negative size, even -1, is refused naming the argument and the size.
  CHECK(what_of([] { iclap::to_cloud<double>(Claimed{-1, 3}, "points"); }) == "points: has a negative size (-1)");
  CHECK(what_of([] { iclap::to_cloud<double>(Claimed{2, -1}, "points"); }) ==
        "points: has a negative dimension (-1)");
  CHECK(iclap::to_cloud<double>(Claimed{0, 0}).size() == 0);
  // The first point that differs from point 0 is named, also point 1 and
  // the last one.
  for (std::size_t bad_at : {1u, 3u}) {
    CAPTURE(bad_at);
    std::vector<Eigen::VectorXd> uneven(4, Eigen::Vector3d(1, 2, 3));
    uneven[bad_at] = Eigen::Vector4d(1, 2, 3, 4);
    CHECK(argument_of([&] { iclap::to_cloud<double>(uneven, "touches"); }) ==
          "touches[" + std::to_string(bad_at) + "]");
  }
  // The registration's entry points name their own argument.
  try {
    const iclap::ReferenceCloud<double, 4> r(Touches{});
    FAIL("an empty reference was built");
  } catch (const iclap::EmptyInput& e) {
    CHECK(e.argument() == "points");
  }
  const iclap::ReferenceCloud<double, 4> reference(model_touches());
  const iclap::Icp<double, 4, iclap::Planar> icp;
  Touches bad = model_touches();
  bad[2].word = 0;
  bad[2].position.z() = std::numeric_limits<float>::infinity();
  try {
    icp.align(reference, bad);
    FAIL("an infinite test coordinate was registered");
  } catch (const iclap::NonFiniteValue& e) {
    CHECK(e.argument() == "test");
    CHECK(e.row() == 2);
    CHECK(e.column() == 2);
  }
}

TEST_CASE_TEMPLATE("a user's cloud registers exactly as a matrix of the same values", Scalar, float, double) {
  const Touches model = model_touches();
  const Touches test = moved(model, 0.05f, Eigen::Vector2f(0.004f, -0.003f));
  const Eigen::Vector4d weights(1, 1, 1, 0.002);
  const iclap::ReferenceCloud<Scalar, 4> from_traits(model, weights);
  const iclap::ReferenceCloud<Scalar, 4> from_matrix(as_matrix(model), weights);
  CHECK(from_traits.working_points() == from_matrix.working_points());
  CHECK(from_traits.centroid() == from_matrix.centroid());

  iclap::Icp<Scalar, 4, iclap::Planar> icp;
  icp.termination.max_iterations = 40;
  const auto a = icp.align(from_traits, test);
  const auto b = icp.align(from_matrix, as_matrix(test));
  CHECK(a.iterations == b.iterations);
  CHECK(a.error == b.error);
  CHECK(a.T_model_test.matrix() == b.T_model_test.matrix());
  // The motion is recovered: the inverse of the one applied.
  CHECK(a.converged);
  CHECK(std::abs(static_cast<double>(a.rmse)) < (std::is_same_v<Scalar, float> ? 1e-5 : 1e-7));

  // From an initial guess too.
  typename iclap::Icp<Scalar, 4, iclap::Planar>::Transform guess = a.T_model_test;
  const auto c = icp.align(from_traits, test, guess);
  const auto d = icp.align(from_matrix, as_matrix(test), guess);
  CHECK(c.iterations == d.iterations);
  CHECK(c.T_model_test.matrix() == d.T_model_test.matrix());
}

TEST_CASE("a cloud of run-time dimension registers with Eigen::Dynamic") {
  // Five coordinates: a position and two descriptor values (iCLAP-N).
  Rows model{{}, 5}, test{{}, 5};
  for (int i = 0; i < 30; ++i) {
    const double x = 0.003 * i, y = 0.01 * std::sin(0.4 * i), z = 0.002 * (i % 4);
    model.rows.push_back({x, y, z, 0.1 * (i % 3), 0.05 * (i % 5)});
    test.rows.push_back({x + 0.002, y - 0.001, z, 0.1 * (i % 3), 0.05 * (i % 5)});
  }
  const iclap::ReferenceCloud<double, Eigen::Dynamic> reference(model);
  CHECK(reference.dim() == 5);
  iclap::Icp<double, Eigen::Dynamic, iclap::SpatialRigid> icp;
  const auto r = icp.align(reference, test);
  const auto m = icp.align(reference, iclap::to_cloud<double>(test));
  CHECK(r.T_model_test.matrix() == m.T_model_test.matrix());
  CHECK(r.converged);
  CHECK(std::abs(r.T_model_test.t(0) + 0.002) < 1e-9);
  CHECK(std::abs(r.T_model_test.t(1) - 0.001) < 1e-9);
  // A cloud of another dimension than the reference's is refused, naming it.
  const Rows four{{{0, 0, 0, 0}}, 4};
  CHECK_THROWS_AS(icp.align(reference, four), iclap::DimensionMismatch);
}

namespace {

// Queries around the model touches: the neighbours the searches must agree on.
Eigen::Matrix4Xd queries() {
  Eigen::Matrix4Xd q(4, 60);
  for (int i = 0; i < 60; ++i)
    q.col(i) << 0.0033 * i - 0.01, 0.012 * std::cos(0.7 * i), 0.001 * (i % 5), 0.5 * (i % 7);
  return q;
}

// `Search` built from the user's touches and from a matrix of the same
// values (as Scalar) answers every query alike: the same neighbour at the
// same squared distance.
template <typename Search, typename Scalar, typename Cloud>
void check_same_search(const Cloud& cloud, const typename Search::CloudType& matrix) {
  const Search own(cloud), mine(matrix);
  REQUIRE(own.size() == mine.size());
  const Eigen::Matrix4Xd q = queries();
  for (Eigen::Index i = 0; i < q.cols(); ++i) {
    const Eigen::Matrix<Scalar, 4, 1> p = q.col(i).cast<Scalar>();
    const auto a = own.nearest(p.data()), b = mine.nearest(p.data());
    CHECK(a.index == b.index);
    CHECK(a.squared_distance == b.squared_distance);
  }
}

}  // namespace

TEST_CASE_TEMPLATE("the searches take a user's cloud and answer as for a matrix of the same values", Scalar, float,
                   double) {
  const Touches t = model_touches();
  const iclap::Cloud<Scalar, 4> fixed = as_matrix(t).cast<Scalar>();
  const iclap::Cloud<Scalar, Eigen::Dynamic> dynamic = fixed;
  check_same_search<iclap::KdTreeSearch<Scalar, 4>, Scalar>(t, fixed);
  check_same_search<iclap::BruteForceSearch<Scalar, 4>, Scalar>(t, fixed);
  check_same_search<iclap::AdaptiveSearch<Scalar, 4>, Scalar>(t, fixed);
  check_same_search<iclap::KdTreeSearch<Scalar, Eigen::Dynamic>, Scalar>(t, dynamic);
  check_same_search<iclap::BruteForceSearch<Scalar, Eigen::Dynamic>, Scalar>(t, dynamic);
  check_same_search<iclap::AdaptiveSearch<Scalar, Eigen::Dynamic>, Scalar>(t, dynamic);
  // Refused, naming the points: another dimension, a NaN, no point.
  using Kd = iclap::KdTreeSearch<Scalar, 3>;
  using Brute = iclap::BruteForceSearch<Scalar, 4>;
  using Adaptive = iclap::AdaptiveSearch<Scalar, 4>;
  CHECK_THROWS_AS(Kd{t}, iclap::DimensionMismatch);
  CHECK(argument_of([&] { Kd{t}; }) == "points");
  Touches bad = t;
  bad[3].position.z() = std::numeric_limits<float>::infinity();
  CHECK_THROWS_AS(Brute{bad}, iclap::NonFiniteValue);
  CHECK(argument_of([&] { Brute{bad}; }) == "points");
  CHECK_THROWS_AS(Adaptive{Touches{}}, iclap::EmptyInput);
  CHECK(argument_of([&] { Adaptive{Touches{}}; }) == "points");
}

TEST_CASE("a distance field takes a user's 3-D cloud and samples the field of a matrix of the same values") {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 40; ++i) points.emplace_back(0.001 * i, 0.004 * std::sin(0.3 * i), 0.0005 * (i % 6));
  Eigen::Matrix3Xd matrix(3, 40);
  for (int i = 0; i < 40; ++i) matrix.col(i) = points[static_cast<std::size_t>(i)];
  const iclap::DistanceFieldSettings settings{1e-3, 3e-3};
  const iclap::TruncatedDistanceField own(points, settings), mine(matrix, settings);
  iclap::Index near = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d q(0.0002 * i - 0.002, 0.003 * std::cos(0.11 * i), 0.0001 * (i % 30));
    CHECK(own.squared_distance(q) == mine.squared_distance(q));
    CHECK(own.node_squared_distance(q) == mine.node_squared_distance(q));
    near += own.squared_distance(q) < own.cap();
  }
  CHECK(near > 100);  // most queries lie within the truncation
  // Another dimension is refused, naming the given argument.
  const Touches t = model_touches();
  CHECK_THROWS_AS(iclap::TruncatedDistanceField(t, settings, "objects[2].occupied"), iclap::DimensionMismatch);
  CHECK(argument_of([&] { iclap::TruncatedDistanceField(t, settings, "objects[2].occupied"); }) ==
        "objects[2].occupied");
}
