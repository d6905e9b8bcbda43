// SPDX-License-Identifier: MIT
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

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

namespace {
/// The closest point of `pts` to `q` by the definition: every point's
/// squared distance, the smaller index on ties.
Neighbor<double> scan_of(const Cloud<double, 3>& pts, const Eigen::Vector3d& q) {
  Neighbor<double> best;
  for (Index j = 0; j < pts.cols(); ++j) {
    const double d = detail::squared_distance<3>(q.data(), pts.col(j).data(), 3);
    if (detail::closer(d, j, best.squared_distance, best.index)) {
      best.index = j;
      best.squared_distance = d;
    }
  }
  return best;
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

#if defined(__SSE__) || defined(__x86_64__)
TEST_CASE_TEMPLATE("duplicates tie to the smaller index under flush-to-zero as well", T, float, double) {
  // A program built with -ffast-math starts with FTZ and DAZ set
  // (crtfastmath.o). A subnormal then reads as 0, and the tie bound of a
  // zero distance, 0 + denorm_min, became 0: the duplicate of smaller index
  // in another leaf was never offered (90 of 200 queries answered 600 + j).
  Cloud<T, 3> pts(3, 800);
  const auto base = random_cloud<T, 3>(3, 200, 11);
  for (Index j = 0; j < 200; ++j) {
    pts.col(j) = base.col(j);
    pts.col(200 + j) = base.col(j).cwiseProduct(Eigen::Matrix<T, 3, 1>(-1, 1, 1));
    pts.col(400 + j) = base.col(j).cwiseProduct(Eigen::Matrix<T, 3, 1>(1, -1, 1));
    pts.col(600 + j) = base.col(j);  // exact duplicates
  }
  const KdTreeSearch<T, 3> tree(pts, {1});
  const BruteForceSearch<T, 3> brute(pts);
  const unsigned csr = _mm_getcsr();
  _mm_setcsr(csr | 0x8040u);  // FTZ | DAZ
  Index differ = 0, not_first = 0;
  for (Index j = 0; j < 200; ++j) {
    const auto a = tree.nearest(pts.col(j)), b = brute.nearest(pts.col(j));
    differ += a.index != b.index || a.squared_distance != b.squared_distance;
    not_first += a.index != j;
  }
  _mm_setcsr(csr);
  CHECK(differ == 0);
  CHECK(not_first == 0);
}
#endif

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
  // An Eigen query of another length than the cloud's points is refused
  // (it used to be read past its end).
  const Cloud<double, Eigen::Dynamic> pts = Cloud<double, Eigen::Dynamic>::Zero(3, 5);
  const Eigen::Vector2d short_query(1, 2);
  CHECK_THROWS_AS(KdTreeSearch<double>(pts).nearest(short_query), DimensionMismatch);
  CHECK_THROWS_AS(BruteForceSearch<double>(pts).nearest(short_query), DimensionMismatch);
  CHECK_THROWS_AS(AdaptiveSearch<double>(pts).nearest(short_query), DimensionMismatch);
  CHECK(AdaptiveSearch<double>(pts).nearest(Eigen::Vector3d(0, 0, 0)).index == 0);
}

TEST_CASE_TEMPLATE_DEFINE("copies share the points and stay valid after the original is gone", S, copies_share) {
  S copy;
  CHECK(copy.size() == 0);
  CHECK(copy.dim() == 0);
  CHECK(copy.points().size() == 0);
  CHECK(copy.nearest(Eigen::Vector3d(0, 0, 0)).index == -1);
  CHECK(copy.nearest(Eigen::Vector3d(0, 0, 0)).squared_distance == std::numeric_limits<double>::infinity());
  const auto pts = random_cloud<double, 3>(3, 64, 5);
  {
    const S original(pts);
    copy = original;
    const S second = original;
    CHECK(&second.points() == &original.points());  // one block, not a copy of the points
    CHECK(&copy.points() == &original.points());
  }
  CHECK(copy.size() == 64);
  CHECK(copy.points() == pts);
  const Eigen::Vector3d q(0.1, 0.2, 0.3);
  CHECK(copy.nearest(q).index == scan_of(pts, q).index);
  CHECK(copy.nearest(q).squared_distance == scan_of(pts, q).squared_distance);
}
namespace {
using Adaptive3d = AdaptiveSearch<double, 3>;
}
TEST_CASE_TEMPLATE_INVOKE(copies_share, KdTreeSearch<double, 3>, BruteForceSearch<double, 3>, Adaptive3d);

namespace {
/// The definition the vectorised scan must reproduce bit for bit: every
/// point's squared_distance, the smaller index on ties, NaN never wins.
template <typename T>
Neighbor<T> scan(const Cloud<T, Eigen::Dynamic>& pts, const T* query) {
  Neighbor<T> best;
  for (Index j = 0; j < pts.cols(); ++j) {
    const T d = detail::squared_distance<Eigen::Dynamic>(query, pts.col(j).data(), pts.rows());
    if (detail::closer(d, j, best.squared_distance, best.index)) {
      best.index = j;
      best.squared_distance = d;
    }
  }
  return best;
}

template <typename T>
BruteForceSearch<T> brute_with(const Cloud<T, Eigen::Dynamic>& pts, bool avx2) {
  typename BruteForceSearch<T>::Settings s;
  s.use_avx2 = avx2;
  return BruteForceSearch<T>(pts, s);
}
}  // namespace

TEST_CASE_TEMPLATE("vectorised brute force: both code paths give the scalar scan's answers", T, float, double) {
  // Sizes around the block widths (8 floats, 4 doubles) and dimensions on
  // both sides of the 8-coordinate switch of squared_distance.
  for (Index dim : {1, 2, 3, 4, 7, 8, 9, 16, 75}) {
    for (Index n : {1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 33, 281}) {
      const auto pts = random_cloud<T, Eigen::Dynamic>(dim, n, 1000 + static_cast<std::uint64_t>(dim * 1000 + n));
      const auto avx2 = brute_with<T>(pts, true);
      const auto baseline = brute_with<T>(pts, false);
      const auto queries = random_cloud<T, Eigen::Dynamic>(dim, 20, 5, 1.5);
      for (Index q = 0; q < queries.cols(); ++q) {
        CAPTURE(dim);
        CAPTURE(n);
        const auto expected = scan<T>(pts, queries.col(q).data());
        const auto a = avx2.nearest(queries.col(q).data());
        const auto b = baseline.nearest(queries.col(q).data());
        REQUIRE(expected.index >= 0);
        CHECK(a.index == expected.index);
        CHECK(a.squared_distance == expected.squared_distance);
        CHECK(b.index == expected.index);
        CHECK(b.squared_distance == expected.squared_distance);
      }
    }
  }
}

TEST_CASE_TEMPLATE("vectorised brute force: ties across lanes and blocks go to the smaller index", T, float, double) {
  // The same point at indices in one lane of different blocks (3, 11, 19 for
  // floats), in different lanes of one block (20, 21) and in the last,
  // partly filled block (40), among distinct points.
  Cloud<T, Eigen::Dynamic> pts = random_cloud<T, Eigen::Dynamic>(3, 41, 17, 1.0, 5.0);
  Eigen::Matrix<T, Eigen::Dynamic, 1> p(3);
  p << T(0.25), T(-0.5), T(0.125);
  for (Index j : {Index(40), Index(21), Index(20), Index(19), Index(11), Index(3)}) {
    pts.col(j) = p;
    for (bool avx2 : {true, false}) {
      const auto search = brute_with<T>(pts, avx2);
      CHECK(search.nearest(p.data()).index == j);
      CHECK(search.nearest(p.data()).squared_distance == T(0));
      // A query equidistant from two points: the smaller index.
      Eigen::Matrix<T, Eigen::Dynamic, 1> q = p;
      q(0) += T(0.001);
      CHECK(search.nearest(q.data()).index == j);
    }
  }
}

TEST_CASE("vectorised brute force: non-finite queries and overflowing distances as the scalar scan") {
  const auto pts = random_cloud<float, Eigen::Dynamic>(3, 13, 23, 1e20);
  for (bool avx2 : {true, false}) {
    const auto search = brute_with<float>(pts, avx2);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float with_nan[3] = {0.0f, nan, 0.0f};
    CHECK(search.nearest(with_nan).index == -1);  // every distance is NaN
    // Far beyond float range when squared: the distances overflow to
    // infinity, none is closer than "none", as in the scalar definition.
    const float far[3] = {3e38f, 3e38f, 3e38f};
    const auto expected = scan<float>(pts, far);
    CHECK(search.nearest(far).index == expected.index);
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    CHECK(search.nearest(zero).index == scan<float>(pts, zero).index);
  }
  CHECK(BruteForceSearch<float, 3>().nearest(Eigen::Vector3f(0, 0, 0)).index == -1);
}

TEST_CASE_TEMPLATE("adaptive search: brute force on small clouds, a kd-tree on large ones, the same answers", T, float,
                   double) {
  static_assert(detail::has_hinted_nearest<AdaptiveSearch<T, 3>, T>::value);
  for (Index n : {5, 300, 682, 683, 3000}) {
    const auto pts = random_cloud<T, 3>(3, n, 31 + static_cast<std::uint64_t>(n));
    const AdaptiveSearch<T, 3> adaptive(pts);  // default: at most 2048 coordinates by brute force
    CHECK(adaptive.uses_tree() == (3 * n > 2048));
    typename AdaptiveSearch<T, 3>::Settings tree_only, brute_only;
    tree_only.brute_force_max_coordinates = 0;
    brute_only.brute_force_max_coordinates = std::numeric_limits<std::size_t>::max();
    const AdaptiveSearch<T, 3> tree(pts, tree_only), brute(pts, brute_only);
    CHECK(tree.uses_tree());
    CHECK(!brute.uses_tree());
    CHECK(adaptive.size() == n);
    CHECK(adaptive.dim() == 3);
    CHECK(adaptive.points() == pts);
    const auto queries = random_cloud<T, 3>(3, 30, 32, 1.3);
    for (Index q = 0; q < queries.cols(); ++q) {
      const auto expected = scan<T>(Cloud<T, Eigen::Dynamic>(pts), queries.col(q).data());
      for (const auto* s : {&adaptive, &tree, &brute}) {
        CHECK(s->nearest(queries.col(q).data()).index == expected.index);
        CHECK(s->nearest(queries.col(q).data()).squared_distance == expected.squared_distance);
        for (Index hint : {expected.index, Index(0), Index(-1), n})
          CHECK(s->nearest(queries.col(q).data(), hint).index == expected.index);
      }
    }
  }
  CHECK_THROWS_AS(AdaptiveSearch<T>(Cloud<T, Eigen::Dynamic>(3, 0)), EmptyInput);
  using Search3 = AdaptiveSearch<T, 3>;
  Cloud<T, 3> bad = Cloud<T, 3>::Zero(3, 2);
  bad(2, 1) = std::numeric_limits<T>::infinity();
  CHECK_THROWS_AS(Search3{bad}, NonFiniteValue);  // by brute force (small) and by the tree
  typename Search3::Settings zero_leaf;
  zero_leaf.brute_force_max_coordinates = 0;
  CHECK_THROWS_AS(Search3(Cloud<T, 3>(bad), zero_leaf), NonFiniteValue);
  zero_leaf.leaf_max_size = 0;
  CHECK_THROWS_AS(Search3(Cloud<T, 3>::Zero(3, 4), zero_leaf), InvalidArgument);
  typename Search3::Settings small_zero_leaf;  // refused for a cloud brute force would take too
  small_zero_leaf.leaf_max_size = 0;
  CHECK_THROWS_AS(Search3(Cloud<T, 3>::Zero(3, 4), small_zero_leaf), InvalidArgument);
}

TEST_CASE("a hint whose squared distance overflows is no neighbour, as without the hint") {
  // Every squared distance overflows float: no neighbour, hinted or not
  // (the hint was returned with distance inf, and ICP went on with E = inf).
  Cloud<float, 3> p = Cloud<float, 3>::Zero(3, 2);
  p(0, 0) = 1e30f;
  p(0, 1) = 2e30f;
  const KdTreeSearch<float, 3> tree(p);
  const BruteForceSearch<float, 3> brute(p);
  const float q[3] = {-1e30f, 0, 0};
  CHECK(brute.nearest(q).index == -1);
  CHECK(tree.nearest(q).index == -1);
  for (const Index hint : {Index(0), Index(1)}) {
    const auto got = tree.nearest(q, hint);
    CHECK(got.index == -1);
  }
}

TEST_CASE("adaptive search: a cloud of exactly brute_force_max_coordinates coordinates is scanned by brute force") {
  // "Largest cloud, in coordinates (points x dimension), searched by brute
  // force": the limit itself still is, one point more is not.
  CHECK(!AdaptiveSearch<float>(random_cloud<float, Eigen::Dynamic>(4, 512, 41)).uses_tree());  // 2048, the default
  CHECK(AdaptiveSearch<float>(random_cloud<float, Eigen::Dynamic>(4, 513, 41)).uses_tree());
  AdaptiveSearch<double, 3>::Settings s;
  s.brute_force_max_coordinates = 30;
  CHECK(!AdaptiveSearch<double, 3>(random_cloud<double, 3>(3, 10, 42), s).uses_tree());
  CHECK(AdaptiveSearch<double, 3>(random_cloud<double, 3>(3, 11, 42), s).uses_tree());
}
