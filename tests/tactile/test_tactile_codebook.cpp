// SPDX-License-Identifier: MIT
// The k-means codebook, word ordering, the Quantizer concept, bag-of-words
// histograms and E_BoW, and the whole tactile pipeline with user types.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <set>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "iclap/search/kdtree.hpp"
#include "iclap/tactile/tactile.hpp"
#include "../support/child_outcome.hpp"
#include "../support/enum_names.hpp"
#include "../support/errors.hpp"
#include "synthetic_contacts.hpp"

using namespace iclap;
using iclap::test::ContactShape;

// Every public class template, for float and double and both search
// policies, so every member compiles.
template class iclap::KMeansQuantizer<float, 72>;
template class iclap::KMeansQuantizer<double>;
template class iclap::KMeansQuantizer<float, Eigen::Dynamic, KdTreeSearch<float>>;
template class iclap::KMeansQuantizer<double, 3, KdTreeSearch<double, 3>>;

namespace {

/// `per_blob` points around each of `centres` (one per column) with noise of
/// half-width `noise`, blob after blob.
template <typename Scalar, int Dim>
Cloud<Scalar, Dim> blobs(const Eigen::MatrixXd& centres, Index per_blob, double noise, std::uint64_t seed) {
  Rng rng(seed);
  Cloud<Scalar, Dim> x(centres.rows(), centres.cols() * per_blob);
  for (Index b = 0; b < centres.cols(); ++b)
    for (Index i = 0; i < per_blob; ++i)
      for (Index d = 0; d < centres.rows(); ++d)
        x(d, b * per_blob + i) = static_cast<Scalar>(centres(d, b) + rng.uniform(-noise, noise));
  return x;
}

Eigen::MatrixXd random_centres(Index dim, Index k, double spread, std::uint64_t seed) {
  Rng rng(seed);
  Eigen::MatrixXd c(dim, k);
  for (Index j = 0; j < k; ++j)
    for (Index d = 0; d < dim; ++d) c(d, j) = rng.uniform(-spread, spread);
  return c;
}

template <typename M>
bool bitwise_equal(const M& a, const M& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(typename M::Scalar) * static_cast<std::size_t>(a.size())) == 0;
}

/// A fit that gave each distinct feature of `x` a word of its own: k words
/// used, none empty, no inertia, and every feature's word centred on it.
template <typename Quantizer, typename Result, typename Features>
void check_word_per_feature(const Quantizer& q, const Result& r, const Features& x, std::size_t k) {
  CHECK(r.inertia == 0.0);
  CHECK(r.empty_clusters == 0);
  const std::set<Index> words(r.labels.data(), r.labels.data() + r.labels.size());
  CHECK(words.size() == k);
  for (Index i = 0; i < x.cols(); ++i) CHECK(q.centres().col(r.labels[i]) == x.col(i));
}

}  // namespace

// ---------------------------------------------------------------------------
TEST_CASE_TEMPLATE("k-means recovers well-separated blobs exactly", T, float, double) {
  const Eigen::MatrixXd truth = random_centres(8, 5, 100.0, 11);
  const auto x = blobs<T, Eigen::Dynamic>(truth, 40, 1.0, 12);
  for (const bool kd : {false, true}) {
    CAPTURE(kd);
    WordIds labels;
    Cloud<T, Eigen::Dynamic> centres;
    if (kd) {
      KMeansQuantizer<T, Eigen::Dynamic, KdTreeSearch<T>> q;
      q.settings.k = 5;
      const auto r = q.fit(x);
      CHECK(r.converged);
      labels = r.labels;
      centres = q.centres();
    } else {
      KMeansQuantizer<T> q;
      q.settings.k = 5;
      const auto r = q.fit(x);
      CHECK(r.converged);
      CHECK(r.stop == KMeansStop::AssignmentsStable);
      labels = r.labels;
      centres = q.centres();
    }
    // Each blob is exactly one word, and the words are distinct.
    std::set<Index> used;
    for (Index b = 0; b < 5; ++b) {
      const Index w = labels[b * 40];
      for (Index i = 0; i < 40; ++i) CHECK(labels[b * 40 + i] == w);
      used.insert(w);
      // The word's centre is the blob's mean.
      const Eigen::VectorXd mean = x.middleCols(b * 40, 40).template cast<double>().rowwise().mean();
      CHECK((centres.col(w).template cast<double>() - mean).cwiseAbs().maxCoeff() < 1e-4);
    }
    CHECK(used.size() == 5);
  }
}

TEST_CASE("k-means: the same seed gives the same codebook bit for bit; policies and pruning agree") {
  // Overlapping clusters so Lloyd needs many iterations and pruning matters.
  const auto x = blobs<float, 16>(random_centres(16, 12, 3.0, 21), 60, 2.5, 22);
  KMeansQuantizer<float, 16> a, b, unpruned;
  KMeansQuantizer<float, 16, KdTreeSearch<float, 16>> tree;
  for (auto* s : {&a.settings, &b.settings, &unpruned.settings}) {
    s->k = 12;
    s->seed = 99;
    s->relative_tolerance = 0.0;  // run to a fixed point
  }
  tree.settings.k = 12;
  tree.settings.seed = 99;
  tree.settings.relative_tolerance = 0.0;
  unpruned.settings.pruning = false;
  const auto ra = a.fit(x);
  const auto rb = b.fit(x);
  const auto ru = unpruned.fit(x);
  const auto rt = tree.fit(x);
  CHECK(ra.iterations > 3);
  // Pruning evaluates far fewer distances than plain Lloyd's n k per step.
  CHECK(ru.distance_evaluations == static_cast<std::int64_t>(ru.assignment_steps) * x.cols() * 12);
  CHECK(ra.distance_evaluations < ru.distance_evaluations / 2);
  CHECK(bitwise_equal(a.centres(), b.centres()));
  CHECK(ra.labels == rb.labels);
  CHECK(ra.inertia == rb.inertia);
  CHECK(bitwise_equal(a.centres(), unpruned.centres()));
  CHECK(ra.labels == ru.labels);
  CHECK(ra.iterations == ru.iterations);
  CHECK(ra.inertia == ru.inertia);
  CHECK(bitwise_equal(a.centres(), tree.centres()));
  CHECK(ra.labels == rt.labels);

  // A different seed is a different draw (here: a different first centre
  // at least changes the codebook's numbering or values).
  KMeansQuantizer<float, 16> c;
  c.settings = a.settings;
  c.settings.seed = 100;
  c.fit(x);
  CHECK_FALSE(bitwise_equal(a.centres(), c.centres()));
}

TEST_CASE_TEMPLATE("k-means: pruned fit equals plain Lloyd with either policy on tie-heavy data", T, float, double) {
  // Features on a small integer lattice: duplicates and exact distance ties
  // everywhere, the worst case for bound-based skipping and tie rules.
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    Rng rng(1000 + seed);
    Cloud<T, Eigen::Dynamic> x(3, 300);
    for (Index j = 0; j < x.cols(); ++j)
      for (Index i = 0; i < 3; ++i) x(i, j) = static_cast<T>(rng.below(4));
    KMeansQuantizer<T> pruned, plain;
    KMeansQuantizer<T, Eigen::Dynamic, KdTreeSearch<T>> plain_tree;
    pruned.settings.k = plain.settings.k = plain_tree.settings.k = 10;
    pruned.settings.seed = plain.settings.seed = plain_tree.settings.seed = seed;
    plain.settings.pruning = plain_tree.settings.pruning = false;
    const auto a = pruned.fit(x);
    const auto b = plain.fit(x);
    const auto c = plain_tree.fit(x);
    CAPTURE(seed);
    CHECK(a.labels == b.labels);
    CHECK(a.labels == c.labels);
    CHECK(a.iterations == b.iterations);
    CHECK(a.inertia == b.inertia);
    CHECK(bitwise_equal(pruned.centres(), plain.centres()));
    CHECK(bitwise_equal(pruned.centres(), plain_tree.centres()));
  }
}

TEST_CASE("k-means: labels equal assign(), batch and single, before and after ordering") {
  const auto x = blobs<float, Eigen::Dynamic>(random_centres(10, 7, 4.0, 31), 30, 2.0, 32);
  for (WordOrdering ordering : {WordOrdering::None, WordOrdering::PrincipalAxis, WordOrdering::NearestNeighbourChain}) {
    CAPTURE(to_string(ordering));
    KMeansQuantizer<float> q;
    q.settings.k = 7;
    q.settings.ordering = ordering;
    q.settings.max_iterations = 3;  // stop early: labels must still match assign()
    const auto r = q.fit(x);
    CHECK(q.size() == 7);
    CHECK(q.dim() == 10);
    CHECK(assign_words(q, x) == r.labels);
    for (Index j = 0; j < x.cols(); ++j) CHECK(q.assign(x.col(j).data()) == r.labels[j]);
    CHECK(r.cluster_sizes.sum() == x.cols());
    for (Index w = 0; w < 7; ++w) CHECK(r.cluster_sizes[w] == (r.labels.array() == w).count());
  }
}

TEST_CASE("k-means: a feature tied between two words gets assign()'s word after a renumbering") {
  // Feature 1 is as close to centre 2 as to centre 0. Before the renumbering
  // it went to old word 0; where the ordering makes that word 1, assign()
  // gives it word 0 (the smaller new id), and so must the labels.
  for (WordOrdering ordering : {WordOrdering::None, WordOrdering::PrincipalAxis, WordOrdering::NearestNeighbourChain}) {
    CAPTURE(to_string(ordering));
    KMeansQuantizer<double, 1> q;
    q.settings.k = 2;
    q.settings.max_iterations = 0;  // keep the given centres
    q.settings.ordering = ordering;
    Cloud<double, 1> f(1, 3);
    f << 0, 1, 2;
    Cloud<double, 1> c(1, 2);
    c << 2, 0;
    const KMeansResult r = q.fit_from(f, c);
    for (Index j = 0; j < 3; ++j) CHECK(r.labels[j] == q.assign(f.col(j)));
    CHECK(r.cluster_sizes[q.assign(f.col(1))] == 2);
  }
}

TEST_CASE("k-means: a finite feature beyond the quantizer's range is out of range, not non-finite") {
  KMeansQuantizer<float> q = KMeansQuantizer<float>::from_centres((Cloud<float, Eigen::Dynamic>(2, 2) << 0, 1, 0, 1).finished());
  for (const double big : {1e16, 1e39, 1e300}) {
    CAPTURE(big);
    // A double beyond float was cast to inf first and reported as NaN/inf.
    CHECK_THROWS_WITH_AS(q.assign(Eigen::Vector2d(big, 0)), doctest::Contains("beyond the float range"), InvalidArgument);
  }
  CHECK_THROWS_AS(q.assign(Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0)), NonFiniteValue);
  CHECK(q.assign(Eigen::Vector2d(0.9, 1.1)) == 1);
}

TEST_CASE("k-means: an empty cluster is re-seeded from the farthest feature") {
  // Two tight blobs and one outlier near blob A; the third initial centre is
  // far from everything, so after the first assignment it is empty.
  Cloud<double, 2> x(2, 21);
  for (Index i = 0; i < 10; ++i) {
    x.col(i) = Eigen::Vector2d(0.0 + 0.01 * static_cast<double>(i), 0.0);
    x.col(10 + i) = Eigen::Vector2d(10.0 + 0.01 * static_cast<double>(i), 0.0);
  }
  x.col(20) = Eigen::Vector2d(0.0, 3.0);  // the feature farthest from its centre
  Cloud<double, 2> initial(2, 3);
  initial << 0.0, 10.0, 500.0,  //
      0.0, 0.0, 500.0;

  KMeansQuantizer<double, 2> q;
  q.settings.k = 3;
  const auto r = q.fit_from(x, initial);
  CHECK(r.reseeded >= 1);
  CHECK(r.empty_clusters == 0);
  CHECK(r.converged);
  // The outlier got the re-seeded word, alone, with the centre on it.
  CHECK(r.labels[20] == 2);
  CHECK(r.cluster_sizes[2] == 1);
  CHECK(q.centres().col(2).isApprox(Eigen::Vector2d(0.0, 3.0)));
  for (Index i = 0; i < 10; ++i) {
    CHECK(r.labels[i] == 0);
    CHECK(r.labels[10 + i] == 1);
  }

  // KeepCentre leaves the word empty and the centre where it was.
  KMeansQuantizer<double, 2> keep;
  keep.settings.k = 3;
  keep.settings.empty_clusters = EmptyClusterPolicy::KeepCentre;
  const auto rk = keep.fit_from(x, initial);
  CHECK(rk.reseeded == 0);
  CHECK(rk.empty_clusters == 1);
  CHECK(rk.cluster_sizes[2] == 0);
  CHECK(keep.centres().col(2) == Eigen::Vector2d(500.0, 500.0));
}

TEST_CASE("k-means: identical features, k = 1, and k = number of distinct features") {
  const Cloud<float, Eigen::Dynamic> same = Cloud<float, Eigen::Dynamic>::Constant(5, 30, 0.25f);
  KMeansQuantizer<float> one;
  one.settings.k = 1;
  const auto r1 = one.fit(same);
  CHECK(r1.converged);
  CHECK(r1.inertia == 0.0);
  CHECK(one.centres().col(0) == same.col(0));

  KMeansQuantizer<float> two;
  two.settings.k = 2;
  try {
    two.fit(same);
    FAIL("k = 2 on one distinct feature accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "settings.k");
    const std::string what = e.what();
    CHECK(what.find("k = 2") != std::string::npos);
    CHECK(what.find("distinct features (1)") != std::string::npos);
  }
  CHECK_FALSE(two.fitted());  // a failed fit leaves the quantizer as it was
  CHECK_THROWS_AS(two.fit_from(same, Cloud<float, Eigen::Dynamic>::Zero(5, 2)), InvalidArgument);

  // k = 1 on spread data: the centre is the mean.
  const auto x = blobs<double, 3>(random_centres(3, 4, 5.0, 41), 25, 1.0, 42);
  KMeansQuantizer<double, 3> mean_only;
  mean_only.settings.k = 1;
  mean_only.fit(x);
  CHECK(mean_only.centres().col(0).isApprox(x.rowwise().mean(), 1e-12));

  // 7 distinct features, each repeated: k = 7 gives each its own word. Float
  // features are summed in double, so a centre of identical members is that
  // member exactly.
  Cloud<float, 3> dup(3, 35);
  const Eigen::MatrixXf distinct = random_centres(3, 7, 1.0, 43).cast<float>();
  for (Index i = 0; i < 35; ++i) dup.col(i) = distinct.col((i * 3) % 7);
  KMeansQuantizer<float, 3> seven;
  seven.settings.k = 7;
  const auto r7 = seven.fit(dup);
  check_word_per_feature(seven, r7, dup, 7);
  seven.settings.k = 8;
  try {
    seven.fit(dup);
    FAIL("k = 8 on 7 distinct features accepted");
  } catch (const InvalidArgument& e) {
    CHECK(std::string(e.what()).find("k = 8 exceeds the number of distinct features (7)") != std::string::npos);
  }
  seven.settings.k = 36;
  try {
    seven.fit(dup);
    FAIL("k = 36 on 35 features accepted");
  } catch (const InvalidArgument& e) {
    CHECK(std::string(e.what()).find("k = 36 exceeds the number of features (35)") != std::string::npos);
  }
}

TEST_CASE("k-means: bad input is a typed error naming argument, row and column") {
  Cloud<float, Eigen::Dynamic> x = Cloud<float, Eigen::Dynamic>::Random(4, 20);
  x(2, 13) = std::numeric_limits<float>::quiet_NaN();
  KMeansQuantizer<float> q;
  q.settings.k = 3;
  try {
    q.fit(x);
    FAIL("NaN accepted");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "features");
    CHECK(e.row() == 2);
    CHECK(e.column() == 13);
  }
  x(2, 13) = std::numeric_limits<float>::infinity();
  CHECK_THROWS_AS(q.fit(x), NonFiniteValue);
  CHECK_THROWS_AS(q.fit(Cloud<float, Eigen::Dynamic>(4, 0)), EmptyInput);

  x(2, 13) = 0.0f;
  const auto setting_error = [&](auto change, const std::string& name) {
    KMeansQuantizer<float> bad;
    bad.settings.k = 3;
    change(bad.settings);
    try {
      bad.fit(x);
      FAIL("accepted bad " << name);
    } catch (const InvalidArgument& e) {
      CHECK(e.argument() == name);
    }
  };
  using S = KMeansQuantizer<float>::Settings;
  setting_error([](S& s) { s.k = 0; }, "settings.k");
  setting_error([](S& s) { s.max_iterations = -1; }, "settings.max_iterations");
  setting_error([](S& s) { s.relative_tolerance = std::numeric_limits<double>::quiet_NaN(); }, "settings.relative_tolerance");

  // assign() before fit, with a wrong length, or with NaN.
  CHECK_THROWS_AS(q.assign(Eigen::VectorXf::Zero(4)), InvalidArgument);
  q.fit(x);
  CHECK_THROWS_AS(q.assign(Eigen::VectorXf::Zero(5)), DimensionMismatch);
  Eigen::VectorXf nan_feature = Eigen::VectorXf::Zero(4);
  nan_feature[1] = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_AS(q.assign(nan_feature), NonFiniteValue);
  CHECK_THROWS_AS(q.fit_from(x, Cloud<float, Eigen::Dynamic>::Zero(3, 3)), DimensionMismatch);
  CHECK_THROWS_AS(q.fit_from(x, Cloud<float, Eigen::Dynamic>::Zero(4, 2)), InvalidArgument);
}

TEST_CASE("k-means: check() throws what fit() would, without fitting") {
  using C = Cloud<float, Eigen::Dynamic>;
  // The type and what() of what `f` throws, "(no error)" if nothing.
  const auto outcome = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const std::exception& e) {
      return std::string(typeid(e).name()) + ": " + e.what();
    }
    return "(no error)";
  };
  // 35 features, 7 distinct (fit() finds that only while seeding); one with
  // a NaN; one whose spread underflows; an empty one; 7 of 7 and 6 of 7
  // distinct.
  C dup(3, 35);
  const Eigen::MatrixXf distinct = random_centres(3, 7, 1.0, 43).cast<float>();
  for (Index i = 0; i < 35; ++i) dup.col(i) = distinct.col((i * 3) % 7);
  C nan = dup;
  nan(1, 20) = std::numeric_limits<float>::quiet_NaN();
  const C tiny = 1e-25f * C::Random(3, 4);
  C six(3, 7);  // 7 features, 6 distinct
  six << dup.leftCols(6), dup.col(0);
  const std::vector<C> sets = {dup, nan, tiny, C(3, 0), dup.leftCols(7), six};
  std::vector<std::string> refusals;
  for (const Index k : {Index(0), Index(1), Index(6), Index(7), Index(8), Index(35), Index(36)})
    for (std::size_t i = 0; i < sets.size(); ++i)
      for (const int iterations : {-1, 5}) {
        CAPTURE(k);
        CAPTURE(i);
        CAPTURE(iterations);
        KMeansQuantizer<float> q;
        q.settings.k = k;
        q.settings.max_iterations = iterations;
        const std::string checked = outcome([&] { q.check(sets[i]); });
        CHECK(!q.fitted());
        const std::string fitted = outcome([&] { q.fit(sets[i]); });
        CHECK(checked == fitted);
        CHECK(q.fitted() == (fitted == "(no error)"));
        refusals.push_back(checked);
      }
  // The cases reach every refusal, the seeding one among them, and a fit.
  for (const char* reason : {"(no error)", "settings.k: must be at least 1", "settings.max_iterations",
                             "exceeds the number of features (35)", "k = 8 exceeds the number of distinct features (7)",
                             "k = 7 exceeds the number of distinct features (6)", "features: ", "underflow"}) {
    const std::string text = reason;
    CAPTURE(text);
    CHECK(std::any_of(refusals.begin(), refusals.end(),
                      [&](const std::string& r) { return r.find(text) != std::string::npos; }));
  }
  static_assert(is_checkable_quantizer_v<KMeansQuantizer<float>, Eigen::MatrixXf>);
  static_assert(is_checkable_quantizer_v<KMeansQuantizer<double, 3>, Cloud<double, 3>>);
}

TEST_CASE_TEMPLATE("k-means: features whose squared distances the scalar type cannot hold are refused", T, float,
                   double) {
  using C = Cloud<T, Eigen::Dynamic>;
  const bool is_float = std::is_same_v<T, float>;
  // Beyond largest_coordinate: every squared distance of a negative feature
  // to the positive seeds overflowed, it had no nearest centre, and its
  // index -1 was used (heap-buffer-overflow).
  C huge(1, 8);
  const T big = static_cast<T>(is_float ? 3e19 : 1e160);
  huge << -big, -0.9f * big, -0.8f * big, -0.7f * big, big, 0.9f * big, 0.8f * big, 0.7f * big;
  KMeansQuantizer<T> q;
  q.settings.k = 2;
  try {
    q.fit(huge);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "features");
    CHECK_MESSAGE(std::string(e.what()).find("at row 0, column 0 is beyond the") != std::string::npos, e.what());
  }
  CHECK(!q.fitted());
  CHECK_THROWS_AS(q.fit_from(C::Constant(1, 8, T(1)), huge.leftCols(2)), InvalidArgument);
  CHECK_THROWS_AS((void)KMeansQuantizer<T>::from_centres(huge.leftCols(2)), InvalidArgument);
  // Below smallest_spread: squared distances underflowed, distinct features
  // looked identical ("k = 2 exceeds the number of distinct features (1)"
  // for 6 distinct ones) and pruned labels differed from plain Lloyd's.
  C tiny(1, 6);
  const T small = static_cast<T>(is_float ? 1e-25 : 1e-200);
  for (Index j = 0; j < 6; ++j) tiny(0, j) = small * static_cast<T>(j);
  try {
    q.fit(tiny);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "features");
    CHECK_MESSAGE(std::string(e.what()).find("underflow") != std::string::npos, e.what());
  }
  // Within range at both ends it fits, and a test feature out of range is
  // refused by assign() naming it.
  huge /= static_cast<T>(is_float ? 1e5 : 1e11);
  q.fit(huge);
  CHECK(q.assign(huge.col(0)) != q.assign(huge.col(4)));
  Eigen::Matrix<T, Eigen::Dynamic, 1> far(1);
  far(0) = big;
  try {
    (void)q.assign(far);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "feature");
  }
}

TEST_CASE_TEMPLATE("k-means: pruned labels equal plain Lloyd's at the smallest spread allowed", T, float, double) {
  // All features at 1e-21 (float) made the pruned labels differ from plain
  // Lloyd's (their squared distances are subnormal, outside the pruning's
  // relative margin); such features are now refused (above). At a spread
  // just above smallest_spread, features within `step` of one another near
  // 0 still have subnormal or zero squared distances; the labels must stay
  // those of plain Lloyd.
  const bool is_float = std::is_same_v<T, float>;
  const double step = is_float ? 1e-23 : 1e-162, high = is_float ? 2e-12 : 2e-138;
  for (std::uint64_t seed = 0; seed < 16; ++seed) {
    Rng rng(500 + seed);
    Cloud<T, Eigen::Dynamic> x(1, 120);
    for (Index j = 0; j < x.cols(); ++j)
      x(0, j) = static_cast<T>(j < 100 ? step * rng.uniform(0, 1) : high * (0.5 + 0.5 * rng.uniform(0, 1)));
    KMeansQuantizer<T> pruned, plain;
    pruned.settings.k = plain.settings.k = 12;
    pruned.settings.seed = plain.settings.seed = seed;
    plain.settings.pruning = false;
    const auto a = pruned.fit(x);
    const auto b = plain.fit(x);
    CAPTURE(seed);
    CHECK(a.labels == b.labels);
    CHECK(a.inertia == b.inertia);
    CHECK(bitwise_equal(pruned.centres(), plain.centres()));
    CHECK(assign_words(pruned, x) == a.labels);
  }
}

TEST_CASE("k-means: iteration limit, progress and from_centres") {
  const auto x = blobs<float, Eigen::Dynamic>(random_centres(6, 9, 3.0, 51), 40, 2.5, 52);
  KMeansQuantizer<float> q;
  q.settings.k = 9;
  q.settings.max_iterations = 0;
  const auto r0 = q.fit(x);
  CHECK_FALSE(r0.converged);
  CHECK(r0.stop == KMeansStop::MaxIterations);
  CHECK(r0.iterations == 0);
  CHECK(assign_words(q, x) == r0.labels);

  std::vector<std::size_t> done;
  std::size_t total = 0;
  q.settings.max_iterations = 50;
  const auto r = q.fit(x, [&](std::size_t d, std::size_t t) {
    done.push_back(d);
    total = t;
  });
  CHECK(total == 50);
  REQUIRE(done.size() >= 2);
  CHECK(std::is_sorted(done.begin(), done.end()));
  CHECK(done.back() == 50);
  CHECK(r.iterations <= 50);

  const auto copy = KMeansQuantizer<float>::from_centres(q.centres());
  CHECK(copy.size() == 9);
  CHECK(assign_words(copy, x) == assign_words(q, x));
  CHECK_THROWS_AS(KMeansQuantizer<float>::from_centres(Cloud<float, Eigen::Dynamic>(6, 0)), EmptyInput);
}

TEST_CASE("word ordering: neighbouring ids are neighbouring centroids") {
  // 8 clusters on a line through 12-D space, numbered in a scrambled order by
  // plain k-means; both orderings must number them along the line.
  const Eigen::VectorXd direction = random_centres(12, 1, 1.0, 61).col(0).normalized();
  Eigen::MatrixXd truth(12, 8);
  const double positions[8] = {5, -2, 9, 0, 14, -7, 3, 11};
  for (Index j = 0; j < 8; ++j) truth.col(j) = 10.0 * positions[j] * direction;
  const auto x = blobs<double, Eigen::Dynamic>(truth, 20, 0.5, 62);

  KMeansQuantizer<double> plain;
  plain.settings.k = 8;
  const auto rp = plain.fit(x);
  for (WordOrdering ordering : {WordOrdering::PrincipalAxis, WordOrdering::NearestNeighbourChain}) {
    CAPTURE(to_string(ordering));
    KMeansQuantizer<double> q;
    q.settings.k = 8;
    q.settings.ordering = ordering;
    const auto r = q.fit(x);
    std::vector<double> along(8);
    for (Index w = 0; w < 8; ++w) along[static_cast<std::size_t>(w)] = q.centres().col(w).dot(direction);
    const bool increasing = std::is_sorted(along.begin(), along.end());
    const bool decreasing = std::is_sorted(along.rbegin(), along.rend());
    CHECK((increasing || decreasing));
    // Ordering only renames: same partition, inertia and set of centres.
    CHECK(r.inertia == rp.inertia);
    for (Index i = 0; i < x.cols(); ++i)
      for (Index j = 0; j < x.cols(); ++j)
        if (rp.labels[i] == rp.labels[j]) CHECK(r.labels[i] == r.labels[j]);
    for (Index w = 0; w < 8; ++w) CHECK(q.centres().col(w) == plain.centres().col(plain.assign(q.centres().col(w))));
  }
  // None keeps the clustering's numbering, which here is not along the line.
  std::vector<double> along(8);
  for (Index w = 0; w < 8; ++w) along[static_cast<std::size_t>(w)] = plain.centres().col(w).dot(direction);
  CHECK_FALSE((std::is_sorted(along.begin(), along.end()) || std::is_sorted(along.rbegin(), along.rend())));
  CHECK(word_order(plain.centres(), WordOrdering::None) == std::vector<Index>{0, 1, 2, 3, 4, 5, 6, 7});
  // Mirror-image centres project equally on the principal axis: ties go to
  // the smaller old id, and of the two ends (0 and 5, equally far) the
  // smaller id's projection is the positive one. The eigenvector's rounding
  // decided both before (0 2 1 3 4 5 for most y, 5 3 4 1 2 0 for y = 0.1).
  for (const double y : {0.5, 0.3, 0.25, 0.1, 0.7})
    for (const double s : {1.0, -1.0}) {
      CAPTURE(y);
      CAPTURE(s);
      Cloud<double, 2> c(2, 6);
      c << 0, 1, 1, 2, 2, 3,  //
          0, s * y, -s * y, s * y, -s * y, 0;
      CHECK(word_order(c, WordOrdering::PrincipalAxis) == std::vector<Index>{5, 3, 4, 1, 2, 0});
    }
}

TEST_CASE("word ordering: every ordering has its documented, distinct name") {
  const std::pair<WordOrdering, std::string> names[] = {
      {WordOrdering::None, "none"},
      {WordOrdering::PrincipalAxis, "principal_axis"},
      {WordOrdering::NearestNeighbourChain, "nearest_neighbour_chain"},
  };
  iclap::test::check_enum_names(names, static_cast<WordOrdering>(7));
}

TEST_CASE("k-means: every stop reason has its documented, distinct name") {
  const std::pair<KMeansStop, std::string> names[] = {
      {KMeansStop::AssignmentsStable, "assignments_stable"},
      {KMeansStop::RelativeChange, "relative_change"},
      {KMeansStop::MaxIterations, "max_iterations"},
  };
  iclap::test::check_enum_names(names, static_cast<KMeansStop>(5));
}

// ---------------------------------------------------------------------------
TEST_CASE("bag of words: histograms and the histogram intersection distance") {
  const WordHistogram h = word_histogram(std::vector<Index>{0, 2, 2, 3}, 4);
  CHECK(h.sum() == doctest::Approx(1.0));
  CHECK(h[0] == 0.25);
  CHECK(h[1] == 0.0);
  CHECK(h[2] == 0.5);
  CHECK(h[3] == 0.25);
  CHECK(word_histogram(WordIds::Constant(3, 1), 2) == Eigen::Vector2d(0.0, 1.0));

  CHECK(histogram_intersection_distance(h, h) == doctest::Approx(0.0));
  const WordHistogram disjoint = word_histogram(std::vector<int>{1, 1}, 4);
  CHECK(histogram_intersection_distance(h, disjoint) == 1.0);
  // 1 - (min(.25,.5) + min(.5,.5)) = 0.25
  const WordHistogram other = word_histogram(std::vector<int>{0, 2}, 4);
  CHECK(histogram_intersection_distance(h, other) == doctest::Approx(0.25));
  CHECK(histogram_intersection_distance(other, h) == doctest::Approx(0.25));  // symmetric when normalised

  // Empty inputs and malformed histograms are errors.
  CHECK_THROWS_AS(word_histogram(std::vector<Index>{}, 4), EmptyInput);
  CHECK_THROWS_AS(word_histogram(std::vector<Index>{0, 4}, 4), InvalidArgument);
  CHECK_THROWS_AS(word_histogram(std::vector<Index>{-1}, 4), InvalidArgument);
  CHECK_THROWS_AS(word_histogram(std::vector<Index>{0}, 0), InvalidArgument);
  CHECK_THROWS_AS(histogram_intersection_distance(Eigen::VectorXd(), h), EmptyInput);
  CHECK_THROWS_AS(histogram_intersection_distance(h, Eigen::VectorXd()), EmptyInput);
  CHECK_THROWS_AS(histogram_intersection_distance(h, Eigen::Vector3d(0.5, 0.5, 0.0)), DimensionMismatch);
  try {
    histogram_intersection_distance(h, Eigen::Vector4d(1, 1, 0, 0));
    FAIL("unnormalised histogram accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "h_class");
  }
  CHECK_THROWS_AS(histogram_intersection_distance(Eigen::Vector2d(1.5, -0.5), Eigen::Vector2d(0.5, 0.5)), InvalidArgument);

  // Per-group histograms (e.g. one per object).
  const Eigen::MatrixXd per_object = word_histograms(std::vector<Index>{0, 1, 1, 2, 2, 2}, std::vector<Index>{0, 0, 0, 1, 1, 2}, 3, 3);
  CHECK(per_object.col(0).isApprox(Eigen::Vector3d(1.0 / 3, 2.0 / 3, 0.0)));
  CHECK(per_object.col(1) == Eigen::Vector3d(0, 0, 1));
  CHECK(per_object.col(2) == Eigen::Vector3d(0, 0, 1));
  CHECK_THROWS_AS(word_histograms(std::vector<Index>{0, 1}, std::vector<Index>{0}, 3, 1), DimensionMismatch);
  CHECK_THROWS_AS(word_histograms(std::vector<Index>{0, 1}, std::vector<Index>{0, 0}, 3, 2), EmptyInput);
  CHECK_THROWS_AS(word_histograms(std::vector<Index>{0, 1}, std::vector<Index>{0, 2}, 3, 2), InvalidArgument);
  CHECK_THROWS_AS(word_histograms(std::vector<Index>{}, std::vector<Index>{}, 3, 1), EmptyInput);
}

// ---------------------------------------------------------------------------
namespace {

/// A user descriptor defined outside the library: the fraction of taxels
/// above 25%, 50% and 75% of the peak, and the peak's share of the total.
struct ShapeFractions {
  Eigen::Vector4d compute(const TactileImage& image) const {
    const double peak = image.max();
    if (!(peak > 0)) return Eigen::Vector4d::Zero();
    const auto n = static_cast<double>(image.size());
    return {static_cast<double>(image.count_above(0.25 * peak)) / n,
            static_cast<double>(image.count_above(0.5 * peak)) / n,
            static_cast<double>(image.count_above(0.75 * peak)) / n, peak / image.sum()};
  }
};

/// A user quantizer defined outside the library: words are the nearest of
/// `k` prototypes taken at even intervals from the training features.
struct EveryNthPrototype {
  Index k = 4;
  Eigen::MatrixXd prototypes;
  template <typename Features>
  void fit(const Features& features) {
    prototypes.resize(features.rows(), k);
    for (Index j = 0; j < k; ++j) prototypes.col(j) = features.col(j * features.cols() / k).template cast<double>();
  }
  template <typename Feature>
  Index assign(const Feature& f) const {
    Index best = 0;
    (prototypes.colwise() - f.template cast<double>()).colwise().squaredNorm().minCoeff(&best);
    return best;
  }
  Index size() const { return prototypes.cols(); }
};

/// A broken quantizer: returns an id outside its vocabulary.
struct OffByOne {
  template <typename F>
  void fit(const F&) {}
  template <typename F>
  Index assign(const F&) const { return 2; }
  Index size() const { return 2; }
};
struct NoAssign {
  template <typename F>
  void fit(const F&) {}
  Index size() const { return 1; }
};

/// Training and test touches of three synthetic objects that differ in the
/// mix of contact shapes they produce.
struct Objects {
  std::vector<TactileImage> train, test;
  std::vector<Index> train_object, test_object;
};
Objects make_objects(std::uint64_t seed) {
  const std::vector<ContactShape> shapes{ContactShape::Blob, ContactShape::Ridge, ContactShape::Edge,
                                         ContactShape::Corner, ContactShape::Flat};
  const std::vector<std::vector<double>> mix{{8, 1, 0.5, 0.5, 0}, {0.5, 8, 1, 0, 0.5}, {0, 0.5, 6, 3, 0.5}};
  Objects o;
  Rng rng(seed);
  for (Index object = 0; object < 3; ++object) {
    for (const auto& p : test::synthetic_contacts(120, rng, shapes, mix[static_cast<std::size_t>(object)])) {
      o.train.emplace_back(p);
      o.train_object.push_back(object);
    }
    for (const auto& p : test::synthetic_contacts(40, rng, shapes, mix[static_cast<std::size_t>(object)])) {
      o.test.emplace_back(p);
      o.test_object.push_back(object);
    }
  }
  return o;
}

/// Descriptor -> quantizer fit -> words -> histograms -> E_BoW: returns the
/// number of the three test sets whose nearest class is their own object.
template <typename Descriptor, typename Quantizer>
int pipeline_correct(const Descriptor& descriptor, Quantizer& quantizer, const Objects& o, Index k) {
  const auto train_features = extract_features(descriptor, o.train);
  quantizer.fit(train_features);
  const WordIds train_words = assign_words(quantizer, train_features);
  const Eigen::MatrixXd h_class = word_histograms(train_words, o.train_object, k, 3);
  const WordIds test_words = assign_words(quantizer, extract_features(descriptor, o.test));
  const Eigen::MatrixXd h_test = word_histograms(test_words, o.test_object, k, 3);
  int correct = 0;
  for (Index t = 0; t < 3; ++t) {
    Index best = -1;
    double best_distance = 2.0;
    for (Index c = 0; c < 3; ++c) {
      const double e = histogram_intersection_distance(h_test.col(t), h_class.col(c));
      CHECK(e >= 0.0);
      CHECK(e <= 1.0);
      if (e < best_distance) {
        best_distance = e;
        best = c;
      }
    }
    if (best == t) ++correct;
  }
  return correct;
}

}  // namespace

TEST_CASE("quantizer concept: shipped and user types model it, others do not") {
  static_assert(is_quantizer_for_v<KMeansQuantizer<float, 72>, Cloud<float, 72>>);
  static_assert(is_quantizer_for_v<KMeansQuantizer<float>, Cloud<float, 72>>);  // via Dynamic
  static_assert(is_quantizer_for_v<EveryNthPrototype, Eigen::MatrixXd>);
  static_assert(!is_quantizer_for_v<NoAssign, Eigen::MatrixXd>);
  static_assert(!is_quantizer_for_v<int, Eigen::MatrixXd>);
  static_assert(!is_quantizer_for_v<EveryNthPrototype, std::vector<double>>);
  CHECK(true);  // compile-time checks above
}

TEST_CASE("pipeline with a user descriptor and the k-means codebook") {
  const Objects o = make_objects(71);
  const ShapeFractions descriptor;
  KMeansQuantizer<double, 4> quantizer;
  quantizer.settings.k = 12;
  CHECK(pipeline_correct(descriptor, quantizer, o, 12) == 3);
}

TEST_CASE("pipeline with Tactile-SIFT and a user quantizer") {
  const Objects o = make_objects(72);
  EveryNthPrototype quantizer;
  quantizer.k = 30;
  CHECK(pipeline_correct(TactileSift<>(), quantizer, o, 30) == 3);
}

TEST_CASE("pipeline with the paper's setting: Tactile-SIFT and k-means") {
  const Objects o = make_objects(73);
  KMeansQuantizer<float, 72> quantizer;
  quantizer.settings.k = 20;
  CHECK(pipeline_correct(TactileSift<>(), quantizer, o, 20) == 3);
}

TEST_CASE("assign_words catches a quantizer that returns ids outside its vocabulary") {
  const Eigen::MatrixXd features = Eigen::MatrixXd::Zero(3, 4);
  try {
    assign_words(OffByOne(), features);
    FAIL("out-of-range word accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "quantizer");
    CHECK(std::string(e.what()).find("word 2") != std::string::npos);
  }
  CHECK_THROWS_AS(assign_words(KMeansQuantizer<double>(), features), InvalidArgument);  // not fitted
}

TEST_CASE("k-means++: the first centre is uniform, the next ones weighted by the squared distance") {
  // With no Lloyd iteration (max_iterations = 0) the codebook is the seeding.
  // k = 1 on four distinct features: each is the first centre about a
  // quarter of the time (400 seeds: 100 expected, 8.7 standard deviations).
  Cloud<double, 1> four(1, 4);
  four << 0.0, 1.0, 2.0, 3.0;
  const auto seeding = [](const Cloud<double, 1>& x, Index k, std::uint64_t seed) {
    KMeansQuantizer<double, 1> q;
    q.settings.k = k;
    q.settings.seed = seed;
    q.settings.max_iterations = 0;
    q.fit(x);
    return Eigen::MatrixXd(q.centres());
  };
  std::vector<int> first(4, 0);
  for (std::uint64_t seed = 0; seed < 400; ++seed)
    ++first[static_cast<std::size_t>(std::lround(seeding(four, 1, seed)(0, 0)))];
  for (const int count : first) CHECK((count >= 65 && count <= 135));
  // k = 2 on 98 features at 0, one at 1 and one at 2: after a first centre at
  // 0, the one at 2 is drawn with probability 4 / (1 + 4) (D^2; 2/3 by the
  // distance D). With the first centre at 1 or 2 (2%): 0.794 in all; 1000
  // seeds: 794 expected, 12.8 standard deviations (D would give 663).
  Cloud<double, 1> x = Cloud<double, 1>::Zero(1, 100);
  x(0, 98) = 1.0;
  x(0, 99) = 2.0;
  int far = 0;
  for (std::uint64_t seed = 0; seed < 1000; ++seed) far += (seeding(x, 2, seed).array() == 2.0).any() ? 1 : 0;
  CHECK(far >= 745);
  CHECK(far <= 845);
}

TEST_CASE("k-means: a re-seed never takes a cluster's only feature; a last re-seed is assigned again") {
  // Ten features near the origin, one 3 above it, and one alone at (90, 0)
  // nearest the second initial centre; the third centre gets nothing. The
  // farthest feature from its centre is the lone one (distance 10), but
  // moving it would empty its cluster: the outlier at (0, 3) is re-seeded.
  Cloud<double, 2> x(2, 12);
  for (Index i = 0; i < 10; ++i) x.col(i) = Eigen::Vector2d(0.01 * static_cast<double>(i), 0.0);
  x.col(10) = Eigen::Vector2d(0.0, 3.0);
  x.col(11) = Eigen::Vector2d(90.0, 0.0);
  Cloud<double, 2> initial(2, 3);
  initial << 0.0, 100.0, 500.0,  //
      0.0, 0.0, 500.0;
  KMeansQuantizer<double, 2> q;
  q.settings.k = 3;
  const auto r = q.fit_from(x, initial);
  CHECK(r.reseeded == 1);
  CHECK(r.empty_clusters == 0);
  CHECK(r.labels[10] == 2);
  CHECK(r.labels[11] == 1);
  CHECK(q.centres().col(1) == Eigen::Vector2d(90.0, 0.0));
  CHECK(q.centres().col(2) == Eigen::Vector2d(0.0, 3.0));

  // A re-seed in the last allowed step (max_iterations = 0: the first
  // assignment's) moves a centre after the features were assigned: here
  // onto (0, 3.1), which the feature at (0, 3) is then nearer to than to
  // the origin; the final labels are assign()'s.
  Cloud<double, 2> y(2, 12);
  for (Index i = 0; i < 9; ++i) y.col(i) = Eigen::Vector2d(0.01 * static_cast<double>(i), 0.0);
  y.col(9) = Eigen::Vector2d(10.0, 0.0);
  y.col(10) = Eigen::Vector2d(0.0, 3.0);
  y.col(11) = Eigen::Vector2d(0.0, 3.1);
  Cloud<double, 2> start = initial;
  start.col(1) = Eigen::Vector2d(10.0, 0.0);
  KMeansQuantizer<double, 2> last;
  last.settings.k = 3;
  last.settings.max_iterations = 0;
  const auto rl = last.fit_from(y, start);
  CHECK(rl.stop == KMeansStop::MaxIterations);
  CHECK(rl.reseeded == 1);
  CHECK(rl.labels[10] == 2);
  CHECK(rl.labels[11] == 2);
  CHECK(rl.labels == assign_words(last, y));
  CHECK(rl.cluster_sizes == (WordIds(3) << 9, 1, 2).finished());
  // (0, 3) to (0, 3.1), and the nine features 0.01 i from the origin.
  CHECK(rl.inertia == doctest::Approx(0.01 + 0.0204).epsilon(1e-12));
}

TEST_CASE("k-means: k equal to the number of features gives each its own word") {
  Cloud<double, 2> x(2, 5);
  x << 0.0, 1.0, 4.0, 9.0, 16.0,  //
      0.0, 0.0, 0.0, 0.0, 1.0;
  KMeansQuantizer<double, 2> q;
  q.settings.k = 5;
  check_word_per_feature(q, q.fit(x), x, 5);
}

TEST_CASE("E_BoW of normalised histograms: clamped at 0 despite rounding, and the sum checked within 1e-6") {
  // Tenths of 2, 4, 3 and 1 add up to 1 + 2.2e-16 in double: the
  // intersection of the histogram with itself is 0, not -2.2e-16.
  const WordHistogram tenths = word_histogram(std::vector<Index>{0, 0, 1, 1, 1, 1, 2, 2, 2, 3}, 4);
  CHECK(histogram_intersection_distance(tenths, tenths) == 0.0);
  // A histogram that sums to 1.01 or 0.999 is not normalised; 1 + 1e-7 is.
  const Eigen::Vector4d h(0.25, 0.25, 0.25, 0.25);
  CHECK_THROWS_WITH_AS(histogram_intersection_distance(h, Eigen::Vector4d(0.26, 0.25, 0.25, 0.25)),
                       "h_class: sums to 1.01, expected 1 (normalise it first)", InvalidArgument);
  CHECK_THROWS_WITH_AS(histogram_intersection_distance(Eigen::Vector4d(0.249, 0.25, 0.25, 0.25), h),
                       "h_test: sums to 0.999, expected 1 (normalise it first)", InvalidArgument);
  CHECK(histogram_intersection_distance(h, Eigen::Vector4d(0.25 + 1e-7, 0.25, 0.25, 0.25)) ==
        doctest::Approx(0.0).epsilon(1e-12));
}

TEST_CASE("assign_words refuses a quantizer without words before asking it") {
  CHECK_THROWS_WITH_AS(assign_words(KMeansQuantizer<double>(), Eigen::MatrixXd::Zero(3, 4)),
                       "quantizer: has no words (is it fitted?)", InvalidArgument);
  CHECK_THROWS_WITH_AS(assign_words(KMeansQuantizer<double>(), Eigen::MatrixXd::Zero(3, 0)),
                       "quantizer: has no words (is it fitted?)", InvalidArgument);
}

TEST_CASE("k-means: relative_tolerance must be finite and >= 0; from_centres makes settings.k the number of centres") {
  Cloud<double, 1> x(1, 4);
  x << 0.0, 1.0, 2.0, 3.0;
  for (const double tolerance : {-1e-9, std::numeric_limits<double>::infinity(), 0.0}) {
    CAPTURE(tolerance);
    KMeansQuantizer<double, 1> q;
    q.settings.k = 2;
    q.settings.relative_tolerance = tolerance;
    CHECK(test::argument_of([&] { q.fit(x); }) == (tolerance == 0.0 ? "(no error)" : "settings.relative_tolerance"));
  }
  const auto q = KMeansQuantizer<double, 1>::from_centres(x.leftCols(3));
  CHECK(q.settings.k == 3);
}

TEST_CASE("word ordering: the nearest-neighbour chain breaks ties by the smaller old id") {
  // Start: ids 0 and 2 are equally far from the mean; the chain starts at 0.
  Cloud<double, Eigen::Dynamic> line(1, 3);
  line << -1.0, 0.0, 1.0;
  CHECK(word_order(line, WordOrdering::NearestNeighbourChain) == std::vector<Index>{0, 1, 2});
  line << 1.0, 0.0, -1.0;
  CHECK(word_order(line, WordOrdering::NearestNeighbourChain) == std::vector<Index>{0, 1, 2});
  // Step: from the far word 3 to word 2 at the origin, then ids 0 and 1 are
  // equally near; 0 comes first.
  Cloud<double, Eigen::Dynamic> fork(2, 4);
  fork << 1.0, -1.0, 0.0, 0.0,  //
      0.0, 0.0, 0.0, 10.0;
  CHECK(word_order(fork, WordOrdering::NearestNeighbourChain) == std::vector<Index>{3, 2, 0, 1});
  fork.row(0) *= -1.0;
  CHECK(word_order(fork, WordOrdering::NearestNeighbourChain) == std::vector<Index>{3, 2, 0, 1});
}

TEST_CASE("word ordering: the principal axis points to the largest projection; mirror pairs are ordered by old id") {
  // Words on a line through 3-D space at positions t (a unique extreme, so
  // the axis' sign is fixed by it), in every numbering: the order is by
  // projection on the axis oriented towards that extreme.
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  for (const std::vector<double>& t : {std::vector<double>{0.0, 1.0, 5.0}, std::vector<double>{0.0, 4.0, 5.0}}) {
    std::vector<Index> perm{0, 1, 2};
    do {
      Cloud<double, 3> c(3, 3);
      std::vector<double> position(3);
      for (std::size_t j = 0; j < 3; ++j) {
        position[j] = t[static_cast<std::size_t>(perm[j])];
        c.col(static_cast<Index>(j)) = position[j] * direction;
      }
      const double mean = (position[0] + position[1] + position[2]) / 3.0;
      std::size_t extreme = 0;
      for (std::size_t j = 1; j < 3; ++j)
        if (std::abs(position[j] - mean) > std::abs(position[extreme] - mean)) extreme = j;
      const double sign = position[extreme] > mean ? 1.0 : -1.0;
      std::vector<Index> expected{0, 1, 2};
      std::sort(expected.begin(), expected.end(), [&](Index a, Index b) {
        return sign * position[static_cast<std::size_t>(a)] < sign * position[static_cast<std::size_t>(b)];
      });
      CAPTURE(position[0]);
      CAPTURE(position[1]);
      CAPTURE(position[2]);
      CHECK(word_order(c, WordOrdering::PrincipalAxis) == expected);
    } while (std::next_permutation(perm.begin(), perm.end()));
  }
  // Pairs mirrored across the axis, rotated by several angles: each pair is
  // a tie, ordered by old id, whichever of the two rounding projects higher.
  for (const double angle : {0.3, 1.1, 2.0, 2.9, 4.4, 5.5}) {
    const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(angle).toRotationMatrix();
    Cloud<double, 2> c(2, 5);
    c << -1.0, 0.0, 3.0, 0.0, -1.0,  //
        -0.4, 0.3, 0.0, -0.3, 0.4;
    c = rotation * c;
    CAPTURE(angle);
    CHECK(word_order(c, WordOrdering::PrincipalAxis) == std::vector<Index>{0, 4, 1, 3, 2});
  }
}

namespace {
/// A broken quantizer: returns a negative id.
struct NegativeId {
  template <typename F>
  void fit(const F&) {}
  template <typename F>
  Index assign(const F&) const { return -1; }
  Index size() const { return 2; }
};
}  // namespace

TEST_CASE("assign_words catches a quantizer that returns a negative id") {
  CHECK_THROWS_WITH_AS(assign_words(NegativeId(), Eigen::MatrixXd::Zero(3, 4)),
                       "quantizer: assigned word -1 to features column 0, outside [0, 2)", InvalidArgument);
}

TEST_CASE("k-means: two words re-seeded in one step; a cluster that gave a feature away keeps its last one") {
  // a, b nearest the first initial centre, c, d the second; the other two
  // words get nothing. b (farthest, 4 from its centre) re-seeds word 2; its
  // cluster then holds only a, so word 3 is re-seeded from the other
  // cluster, with d (0.1 from its centre), although a is farther (1).
  Cloud<double, 2> x(2, 4);
  x << 1.0, 1.0, 100.0, 100.0,  //
      1.0, 6.0, 0.0, 0.1;
  Cloud<double, 2> initial(2, 4);
  initial << 1.0, 100.0, 500.0, 600.0,  //
      2.0, 0.0, 500.0, 600.0;
  KMeansQuantizer<double, 2> q;
  q.settings.k = 4;
  const auto r = q.fit_from(x, initial);
  CHECK(r.reseeded == 2);
  CHECK(r.labels == (WordIds(4) << 0, 2, 1, 3).finished());
  check_word_per_feature(q, r, x, 4);
}

// ---------------------------------------------------------------------------
// Audit (session 50): defects found from a user's side, fixed since.

TEST_CASE("k-means: check() agrees with fit() when only some pairs of features are too close to tell apart") {
  // kmeans.hpp check_features() compares the smallest_spread bound with the
  // largest difference from features.col(0) only. Here it is 1, but 0 and
  // 1e-200 are 1e-400 apart squared: 0 in double. check() counts 3 distinct
  // features (exact comparison) and accepts k = 3; fit() then finds only 2
  // while seeding and throws "k = 3 exceeds the number of distinct features
  // (2)", a count that is wrong and that check() promised to report first.
  Cloud<double, Eigen::Dynamic> x(1, 3);
  x << 0.0, 1e-200, 1.0;
  const auto outcome = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const std::exception& e) {
      return e.what();
    }
    return "(no error)";
  };
  for (const std::uint64_t seed : {0u, 1u, 2u}) {
    CAPTURE(seed);
    KMeansQuantizer<double> q;
    q.settings.k = 3;
    q.settings.seed = seed;
    const std::string checked = outcome([&] { q.check(x); });
    const std::string fitted = outcome([&] { q.fit(x); });
    CHECK(checked == fitted);
    // Whatever is refused, 3 distinct features are not called 2.
    CHECK(fitted.find("distinct features (2)") == std::string::npos);
    // fit() now takes the next distinct feature when squared distances
    // cannot tell the rest apart: three finite words, 0 and 1 on different
    // ones (0 and 1e-200 may share one: no distance in double separates
    // them).
    CHECK(checked == "(no error)");
    REQUIRE(q.size() == 3);
    CHECK(q.centres().allFinite());
    CHECK(q.assign(x.col(0)) != q.assign(x.col(2)));
  }
}

namespace {
/// A quantizer whose ids are std::size_t (an integer, as the concept asks),
/// returning SIZE_MAX, e.g. a "no word" sentinel by mistake.
struct SizeTQuantizer {
  template <typename Features>
  void fit(const Features&) {}
  template <typename Feature>
  std::size_t assign(const Feature&) const {
    return std::numeric_limits<std::size_t>::max();
  }
  std::size_t size() const { return 2; }
};
}  // namespace

TEST_CASE("bag of words: an unsigned word id beyond the range is named by its value, not as a negative one") {
  // bag_of_words.hpp word_histogram / word_histograms and quantizer.hpp
  // assign_words cast every id to Index before the range check, so SIZE_MAX
  // (accepted: the id type need only be integral) was reported as
  // "word -1 ...", a value the caller never had.
  const std::string max = std::to_string(std::numeric_limits<std::size_t>::max());
  const std::vector<std::size_t> words{0, std::numeric_limits<std::size_t>::max()};
  const std::string single = test::what_of([&] { (void)word_histogram(words, 3); });
  CHECK(single.find(max) != std::string::npos);
  CHECK(single.find("word -1") == std::string::npos);
  const std::string grouped =
      test::what_of([&] { (void)word_histograms(words, std::vector<std::size_t>{0, 0}, 3, 1); });
  CHECK(grouped.find(max) != std::string::npos);
  const std::string assigned = test::what_of([&] { (void)assign_words(SizeTQuantizer(), Eigen::MatrixXd::Zero(2, 1)); });
  CHECK(assigned.find(max) != std::string::npos);
  CHECK(assigned.find("word -1") == std::string::npos);
}

TEST_CASE("k-means with a fixed Dim: features of another dimension are a DimensionMismatch, not an Eigen assertion") {
  // kmeans.hpp fit / check / from_centres take `const Features&`
  // (Cloud<Scalar, Dim>); a dynamic matrix of another row count converts
  // implicitly, and Eigen's unchecked resize asserts (abort) in a debug
  // build and, with NDEBUG, fits 3-D words on the 4-row buffer read as 3 rows
  // (fit returns normally, dim() == 3: a silent wrong codebook).
  const Eigen::MatrixXf four = Eigen::MatrixXf::Random(4, 10);
  KMeansQuantizer<float, 3> q;
  q.settings.k = 2;
  CHECK(test::outcome_in_child([&] { q.fit(four); }) == "DimensionMismatch features");
  CHECK(test::outcome_in_child([&] { q.check(four); }) == "DimensionMismatch features");
  CHECK(test::outcome_in_child([&] { (void)KMeansQuantizer<float, 3>::from_centres(four); }) == "DimensionMismatch centres");
  // The right dimension fits (the helper reports no error).
  CHECK(test::outcome_in_child([&] { q.fit(four.topRows(3)); }) == "(no error)");
}
