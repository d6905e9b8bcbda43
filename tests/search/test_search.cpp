// SPDX-License-Identifier: MIT
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "iclap/core/random.hpp"
#include "iclap/search/search.hpp"

using namespace iclap;

namespace {
template <typename Scalar, int Dim>
Cloud<Scalar, Dim> random_cloud(Index dim, Index n, std::uint64_t seed, double scale = 1.0, double offset = 0.0) {
  Rng rng(seed);
  Cloud<Scalar, Dim> c(dim, n);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < dim; ++i) c(i, j) = static_cast<Scalar>(offset + scale * rng.uniform(-1.0, 1.0));
  return c;
}
}  // namespace

TEST_CASE_TEMPLATE("kd-tree answers exactly what brute force answers", T, float, double) {
  for (Index dim : {1, 2, 3, 4, 8, 67}) {
    for (Index n : {1, 2, 3, 5, 17, 300}) {
      const auto pts = random_cloud<T, Eigen::Dynamic>(dim, n, 7 + static_cast<std::uint64_t>(dim * 1000 + n));
      const KdTreeSearch<T> tree(pts);
      const BruteForceSearch<T> brute(pts);
      const auto queries = random_cloud<T, Eigen::Dynamic>(dim, 50, 99, 1.5);
      for (Index q = 0; q < queries.cols(); ++q) {
        const auto a = tree.nearest(queries.col(q).data());
        const auto b = brute.nearest(queries.col(q).data());
        CHECK(a.index == b.index);
        CHECK(a.squared_distance == b.squared_distance);
      }
    }
  }
}

TEST_CASE_TEMPLATE("fixed-dimension tree matches the dynamic one", T, float, double) {
  const auto pts = random_cloud<T, 3>(3, 500, 3);
  const KdTreeSearch<T, 3> fixed(pts);
  const KdTreeSearch<T> dynamic{Cloud<T, Eigen::Dynamic>(pts)};
  const auto queries = random_cloud<T, 3>(3, 100, 4);
  for (Index q = 0; q < queries.cols(); ++q) {
    const auto a = fixed.nearest(queries.col(q));
    const auto b = dynamic.nearest(queries.col(q));
    CHECK(a.index == b.index);
    CHECK(a.squared_distance == b.squared_distance);
  }
}

TEST_CASE("ties go to the smaller index in both policies") {
  // Duplicated points and a query equidistant from a grid of points.
  Cloud<double, 2> pts(2, 6);
  pts << 1, 0, -1, 0, 1, 0,  //
      0, 1, 0, -1, 0, 1;
  const KdTreeSearch<double, 2> tree(pts, {1});
  const BruteForceSearch<double, 2> brute(pts);
  const Eigen::Vector2d origin(0, 0);
  CHECK(tree.nearest(origin).index == 0);
  CHECK(brute.nearest(origin).index == 0);
  const Eigen::Vector2d up(0, 1);
  CHECK(tree.nearest(up).index == 1);  // index 5 is the same point
  CHECK(brute.nearest(up).index == 1);
  CHECK(tree.nearest(up).squared_distance == 0.0);
}

TEST_CASE_TEMPLATE("a warm-start hint never changes the answer", T, float, double) {
  static_assert(detail::has_hinted_nearest<KdTreeSearch<T, 3>, T>::value);
  static_assert(!detail::has_hinted_nearest<BruteForceSearch<T, 3>, T>::value);
  for (Index dim : {2, 3, 8}) {
    const auto pts = random_cloud<T, Eigen::Dynamic>(dim, 400, 21 + static_cast<std::uint64_t>(dim));
    const KdTreeSearch<T> tree(pts);
    const BruteForceSearch<T> brute(pts);
    const auto queries = random_cloud<T, Eigen::Dynamic>(dim, 40, 22, 1.2);
    for (Index q = 0; q < queries.cols(); ++q) {
      const auto expected = brute.nearest(queries.col(q).data());
      // Good, bad and absent hints alike.
      for (Index hint : {expected.index, Index(0), Index(399), Index(q * 7), Index(-1), Index(400)}) {
        const auto got = tree.nearest(queries.col(q).data(), hint);
        CHECK(got.index == expected.index);
        CHECK(got.squared_distance == expected.squared_distance);
      }
    }
  }
  // Ties: hinting the larger of two equal indices still returns the smaller.
  Cloud<T, 2> dup(2, 4);
  dup << 1, 0, 0, 1,  //
      0, 1, 1, 0;
  const KdTreeSearch<T, 2> tree(dup, {1});
  const Eigen::Matrix<T, 2, 1> up(0, 1);
  CHECK(tree.nearest(up.data(), 2).index == 1);
  CHECK(tree.nearest(up.data(), 3).index == 1);
}

TEST_CASE("far clusters and large offsets") {
  Cloud<double, 3> pts = random_cloud<double, 3>(3, 200, 11, 1.0, 1e6);
  pts.rightCols(100) = random_cloud<double, 3>(3, 100, 12, 1.0, -1e6);
  const KdTreeSearch<double, 3> tree(pts);
  const BruteForceSearch<double, 3> brute(pts);
  const auto queries = random_cloud<double, 3>(3, 50, 13, 3.0, 1e6);
  for (Index q = 0; q < queries.cols(); ++q) CHECK(tree.nearest(queries.col(q)).index == brute.nearest(queries.col(q)).index);
}

TEST_CASE("bad inputs are typed errors naming the argument") {
  CHECK_THROWS_AS(KdTreeSearch<double>(Cloud<double, Eigen::Dynamic>(3, 0)), EmptyInput);
  CHECK_THROWS_AS(BruteForceSearch<double>(Cloud<double, Eigen::Dynamic>(3, 0)), EmptyInput);
  Cloud<float, 3> bad = Cloud<float, 3>::Zero(3, 4);
  bad(1, 2) = std::numeric_limits<float>::quiet_NaN();
  try {
    KdTreeSearch<float, 3> t(bad);
    FAIL("expected NonFiniteValue");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "points");
    CHECK(e.row() == 1);
    CHECK(e.column() == 2);
  }
  CHECK_THROWS_AS(KdTreeSearch<double>(Cloud<double, Eigen::Dynamic>::Zero(2, 3), {0}), InvalidArgument);
}

TEST_CASE("copies share the tree and stay valid after the original is gone") {
  KdTreeSearch<double, 3> copy;
  CHECK(copy.size() == 0);
  CHECK(copy.nearest(Eigen::Vector3d(0, 0, 0)).index == -1);
  {
    const KdTreeSearch<double, 3> original(random_cloud<double, 3>(3, 64, 5));
    copy = original;
  }
  const BruteForceSearch<double, 3> brute(random_cloud<double, 3>(3, 64, 5));
  CHECK(copy.size() == 64);
  CHECK(copy.nearest(Eigen::Vector3d(0.1, 0.2, 0.3)).index == brute.nearest(Eigen::Vector3d(0.1, 0.2, 0.3)).index);
}
