// SPDX-License-Identifier: MIT
// Live recognition: the incremental session against from-scratch
// recognition, the stop rule, references, weight choice and the
// cross-validated replay of the confidence-based stop, on small synthetic
// touch data.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/live_session.hpp"
#include "iclap/recognition/recognition.hpp"
#include "../support/enum_names.hpp"
#include "../support/errors.hpp"
#include "synthetic_objects.hpp"

using namespace iclap;

namespace {

/// The shared three-object table with 20 touches per exploration, stored
/// out of time order so that time order has to be restored.
TouchTable synthetic_table(std::uint64_t seed, double feature_noise = 0.05) {
  test::SyntheticTableSettings settings;
  settings.touches_per_exploration = 20;
  settings.feature_noise = feature_noise;
  settings.shuffled_frames = true;
  return test::synthetic_table(seed, settings);
}

KMeansQuantizer<float> codebook() {
  KMeansQuantizer<float> q;
  q.settings.k = 4;
  q.settings.seed = 3;
  return q;
}

/// Touches of exploration `id` (all objects) and of the others.
void split(const TouchTable& t, std::int64_t id, std::vector<Index>& held, std::vector<Index>& train) {
  for (Index i = 0; i < t.size(); ++i)
    (t.exploration[static_cast<std::size_t>(i)] == id ? held : train).push_back(i);
}

std::vector<Index> of_object(const TouchTable& t, const std::vector<Index>& idx, Index o) {
  std::vector<Index> out;
  for (Index i : idx)
    if (t.object[static_cast<std::size_t>(i)] == o) out.push_back(i);
  return out;
}

}  // namespace

namespace {

/// Replays exploration 13 of every object of `t` into live sessions on
/// references from the other explorations and checks every update against
/// an independent recogniser, built by hand from the same classifiers, on
/// the same touches from scratch. `oriented`: the touches go in with their
/// pad normals and contact points (live_touch_of), else through the
/// position / descriptor / word overload. Returns the references.
std::unique_ptr<LiveReferences<>> check_live_equals_scratch(const TouchTable& t, const std::string& method,
                                                          const ClassifierFactory& factory, bool oriented) {
  std::vector<Index> held, train;
  split(t, 13, held, train);
  const Fusion fusion = parse_method(method).fusion;
  auto refs = std::make_unique<LiveReferences<>>(t, train, factory, codebook(), fusion);
  REQUIRE(refs->objects() == t.objects);
  CHECK(refs->vocabulary() == 4);
  CHECK(refs->feature_length() == 4);
  CHECK(refs->touches_per_object() == std::vector<Index>{60, 60, 60});

  KMeansQuantizer<float> q = codebook();
  Eigen::MatrixXf train_features(4, static_cast<Index>(train.size()));
  for (std::size_t j = 0; j < train.size(); ++j) train_features.col(static_cast<Index>(j)) = t.touches.features.col(train[j]);
  q.fit(train_features);
  TouchSet all = t.touches;
  all.words = assign_words(q, t.touches.features);
  std::vector<TouchSet> objects;
  for (Index o = 0; o < 3; ++o) objects.push_back(select_touches(all, of_object(t, train, o)));
  Recognizer scratch(factory());
  scratch.fit(objects, q.size());

  for (Index o = 0; o < 3; ++o) {
    CAPTURE(o);
    const auto test = of_object(t, held, o);
    LiveSession s = refs->session(LiveStopRule{1.0, 1, 0});
    for (std::size_t n = 1; n <= test.size(); ++n) {
      const Index i = test[n - 1];
      CHECK(refs->word(t.touches.features.col(i)) == all.words(i));  // same codebook
      const LiveStop stop = oriented ? s.add_touch(live_touch_of(t.touches, i, all.words(i)))
                                     : s.add_touch(t.touches.positions.col(i), t.touches.features.col(i), all.words(i));
      REQUIRE(s.touches() == static_cast<Index>(n));
      const std::vector<Index> first(test.begin(), test.begin() + static_cast<std::ptrdiff_t>(n));
      const DistanceTable d = scratch.distances(select_touches(all, first));
      for (const auto& c : fusion.classifiers()) {
        CAPTURE(c);
        CHECK(s.distances().get(c) == d.get(c));  // bit-identical: the same computation
      }
      const Eigen::VectorXd fused = fusion.evaluate(d);
      CHECK(s.fused() == fused);
      CHECK(s.best() == decide(fused));
      CHECK(s.ranking().front() == s.best());
      for (std::size_t r = 1; r < s.ranking().size(); ++r) CHECK(fused(s.ranking()[r - 1]) <= fused(s.ranking()[r]));
      CHECK(s.confidence() == decision_confidence(fused));
      CHECK(s.history().size() == n);
      CHECK(s.history().back().best == s.best());
      CHECK(stop == (s.confidence() >= 1.0 ? LiveStop::kConfident : LiveStop::kContinue));
    }
    CHECK(s.touch_set().normals.cols() == (oriented ? static_cast<Index>(test.size()) : 0));
    CHECK(s.best() == o);  // all 20 touches recognise the object
  }
  return refs;
}

}  // namespace

TEST_CASE("live session: each update equals a from-scratch recognition of the same touches") {
  check_live_equals_scratch(synthetic_table(1), "0.5*iclap+0.3*icp+0.2*bow", test::paper_classifiers, false);
}

TEST_CASE("live session: every stop reason has its documented, distinct name") {
  const std::pair<LiveStop, std::string> names[] = {
      {LiveStop::kContinue, "continue"}, {LiveStop::kConfident, "confident"}, {LiveStop::kTouchLimit, "touch limit"}};
  iclap::test::check_enum_names(names, static_cast<LiveStop>(7));
}

TEST_CASE("live session: the stop rule") {
  const TouchTable t = synthetic_table(2);
  std::vector<Index> held, train;
  split(t, 12, held, train);
  const LiveReferences<> refs(t, train, test::paper_classifiers, codebook(), parse_method("0.6*iclap+0.4*icp").fusion);
  const auto test = of_object(t, held, 1);
  auto add = [&](LiveSession& s, std::size_t k) {
    const Index i = test[k];
    return s.add_touch(t.touches.positions.col(i), t.touches.features.col(i), refs.word(t.touches.features.col(i)));
  };
  SUBCASE("threshold 0 stops at min_touches") {
    LiveSession s = refs.session(LiveStopRule{0.0, 3, 0});
    CHECK(add(s, 0) == LiveStop::kContinue);
    CHECK(add(s, 1) == LiveStop::kContinue);
    CHECK(add(s, 2) == LiveStop::kConfident);
    CHECK(s.stop() == LiveStop::kConfident);
  }
  SUBCASE("threshold 1 is never reached with noisy touches: the limit stops") {
    LiveSession s = refs.session(LiveStopRule{1.0, 1, 4});
    for (std::size_t k = 0; k < 3; ++k) CHECK(add(s, k) == LiveStop::kContinue);
    CHECK(add(s, 3) == LiveStop::kTouchLimit);
    CHECK(s.confidence() < 1.0);
  }
  SUBCASE("a middle threshold stops exactly when the confidence first reaches it") {
    // Find the confidences of the whole sequence, then pick a threshold
    // between two of them.
    LiveSession probe = refs.session(LiveStopRule{1.0, 1, 0});
    std::vector<double> c;
    for (std::size_t k = 0; k < test.size(); ++k) {
      add(probe, k);
      c.push_back(probe.confidence());
    }
    std::size_t first_max = 0;
    for (std::size_t k = 0; k < c.size(); ++k)
      if (c[k] > c[first_max]) first_max = k;
    REQUIRE(c[first_max] > 0.1);
    const double threshold = c[first_max];
    LiveSession s = refs.session(LiveStopRule{threshold, 1, 0});
    for (std::size_t k = 0; k < first_max; ++k) CHECK(add(s, k) == LiveStop::kContinue);
    CHECK(add(s, first_max) == LiveStop::kConfident);
    CHECK(s.best() == 1);
  }
  SUBCASE("reset starts a new exploration") {
    LiveSession s = refs.session();
    add(s, 0);
    add(s, 1);
    s.reset();
    CHECK(s.touches() == 0);
    CHECK(s.best() == -1);
    CHECK(s.history().empty());
    add(s, 2);
    CHECK(s.touches() == 1);
  }
}

namespace {

/// The shared table with a pad normal and three contact points per touch:
/// each object tilts its pad by its own amount, so height tells them apart.
TouchTable oriented_table(std::uint64_t seed) {
  TouchTable t = synthetic_table(seed);
  Rng rng(seed + 100);
  const Index n = t.size();
  t.touches.normals.resize(3, n);
  t.touches.contact_points.resize(3, 3 * n);
  t.touches.contact_offsets = {0};
  for (Index i = 0; i < n; ++i) {
    const double tilt = 0.2 * static_cast<double>(t.object[static_cast<std::size_t>(i)] + 1) + rng.uniform(0, 0.05);
    const double azimuth = rng.uniform(-3.0, 3.0);
    t.touches.normals.col(i) = Eigen::Vector3d(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                                               -std::cos(tilt));
    for (Index k = 0; k < 3; ++k)
      t.touches.contact_points.col(3 * i + k) =
          t.touches.positions.col(i) + Eigen::Vector3d(0.002 * static_cast<double>(k - 1), 0.001 * static_cast<double>(k), 0);
    t.touches.contact_offsets.push_back(3 * (i + 1));
  }
  t.touches.validate("oriented table");
  return t;
}

std::vector<std::unique_ptr<Classifier>> oriented_classifiers() {
  std::vector<std::unique_ptr<Classifier>> cs;
  cs.push_back(std::make_unique<BowClassifier>());
  cs.push_back(std::make_unique<HeightClassifier>());
  cs.push_back(std::make_unique<PatchClassifier<float, Planar>>());
  return cs;
}

}  // namespace

TEST_CASE("live session: touches with the pad orientation feed height and patch, as from scratch") {
  const TouchTable t = oriented_table(4);
  const auto refs = check_live_equals_scratch(t, "0.4*height+0.4*patch+0.2*bow", oriented_classifiers, true);
  std::vector<Index> held, train;
  split(t, 13, held, train);
  const Index i = held.front();
  const LiveTouch touch = live_touch_of(t.touches, i, 1);
  REQUIRE(touch.normal);
  CHECK(*touch.normal == Eigen::Vector3d(t.touches.normals.col(i)));
  CHECK(touch.contact_points == t.touches.contact_points.middleCols(3 * i, 3));
  CHECK(touch.position == Eigen::Vector3d(t.touches.positions.col(i)));
  CHECK(touch.feature == t.touches.features.col(i));
  CHECK(touch.word == 1);

  // Every touch of a session carries the pad orientation, or none does.
  LiveSession s = refs->session();
  const LiveTouch full = live_touch_of(t.touches, held.front(), 0);
  LiveTouch bare = live_touch_of(t.touches, held.front(), 0);
  bare.normal.reset();
  CHECK_THROWS_WITH_AS(s.add_touch(bare), doctest::Contains("height"), InvalidArgument);  // the classifier's own check
  CHECK(s.touches() == 0);
  s.add_touch(full);
  CHECK_THROWS_WITH_AS(s.add_touch(bare), "normal: touch 2 has no pad normal but the earlier touches have one",
                       InvalidArgument);
  LiveTouch long_normal = live_touch_of(t.touches, held.front(), 0);
  long_normal.normal = Eigen::Vector3d(0, 0, -1.1);
  CHECK_THROWS_WITH_AS(s.add_touch(long_normal), doctest::Contains("normal: is not a unit vector"), InvalidArgument);
  LiveTouch nan_contact = live_touch_of(t.touches, held.front(), 0);
  nan_contact.contact_points(0, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(s.add_touch(nan_contact), NonFiniteValue);
  CHECK(s.touches() == 1);  // nothing changed
  CHECK_NOTHROW(s.add_touch(full));
  CHECK(s.touches() == 2);
  CHECK(s.touch_set().contact_offsets == std::vector<Index>{0, 3, 6});
  CHECK_THROWS_AS(live_touch_of(t.touches, t.size(), 0), InvalidArgument);

  // A frame with an orientation gives its pad normal and its pressed taxels.
  Frame f;
  f.position = Eigen::Vector3d(0.1, 0.2, 0.03);
  f.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  f.pressures = Eigen::MatrixXd::Zero(14, 6);
  f.pressures(2, 3) = 90;
  f.pressures(7, 1) = 10;  // below the threshold
  const LiveTouch from_frame = live_touch_of(f, 20.0, 0.0034, Eigen::VectorXf::Ones(4), 2);
  REQUIRE(from_frame.normal);
  CHECK((*from_frame.normal - Eigen::Vector3d(0, -std::sin(0.3), std::cos(0.3))).norm() < 1e-12);
  std::vector<Eigen::Vector3d> expected;
  append_contact_points(f, 20.0, 0.0034, expected);
  REQUIRE(expected.size() == 1);
  REQUIRE(from_frame.contact_points.cols() == 1);
  CHECK(from_frame.contact_points.col(0) == expected[0]);
  CHECK(from_frame.position == f.position);
  CHECK(from_frame.word == 2);
  f.orientation.reset();
  const LiveTouch unoriented = live_touch_of(f, 20.0, 0.0034, Eigen::VectorXf::Ones(4), 2);
  CHECK_FALSE(unoriented.normal);
  CHECK(unoriented.contact_points.cols() == 0);
}

// A session keeps a pointer to its recogniser: a temporary does not compile.
static_assert(std::is_constructible_v<LiveSession, const Recognizer&, Fusion, LiveStopRule, Index>);
static_assert(!std::is_constructible_v<LiveSession, Recognizer, Fusion, LiveStopRule, Index>);

TEST_CASE("live session: empty state and errors") {
  const TouchTable t = synthetic_table(3);
  std::vector<Index> held, train;
  split(t, 10, held, train);
  const LiveReferences<> refs(t, train, test::paper_classifiers, codebook(), parse_method("0.5*icp+0.5*bow").fusion);
  LiveSession s = refs.session(LiveStopRule{1.0, 1, 0});
  CHECK(s.touches() == 0);
  CHECK(s.best() == -1);
  CHECK(s.confidence() == 0.0);
  CHECK(s.ranking().empty());
  CHECK(s.fused().size() == 0);
  CHECK(s.distances().objects() == 0);
  CHECK(s.stop() == LiveStop::kContinue);
  CHECK(s.objects() == 3);

  const Eigen::Vector3d p(0.01, 0, 0.01);
  const Eigen::Vector4f f(1, 0, 0, 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(s.add_touch(Eigen::Vector3d(nan, 0, 0), f, 0), NonFiniteValue);
  CHECK_THROWS_WITH_AS(s.add_touch(p, f, 4), "word: 4 is outside [0, 4)", InvalidArgument);
  CHECK_THROWS_AS(s.add_touch(p, f, -1), InvalidArgument);
  CHECK(s.touches() == 0);  // nothing changed
  CHECK(s.add_touch(p, f, 0) == LiveStop::kContinue);
  CHECK_THROWS_AS(s.add_touch(p, Eigen::Vector3f(1, 0, 0), 0), DimensionMismatch);
  CHECK_THROWS_AS(s.add_touch(p, Eigen::Vector4f(std::numeric_limits<float>::infinity(), 0, 0, 0), 0),
                  NonFiniteValue);
  CHECK(s.touches() == 1);
  CHECK(s.best() >= 0);

  CHECK_THROWS_AS(refs.word(Eigen::Vector3f(1, 0, 0)), DimensionMismatch);
  // Stop rules.
  CHECK_THROWS_AS(refs.session(LiveStopRule{1.5, 1, 0}), InvalidArgument);
  // Every digit of a confidence just above 1, not std::to_string's "1.000000".
  CHECK_THROWS_WITH_AS((LiveStopRule{1.000000001, 1, 0}.validate()), "confidence: must be in [0, 1], got 1.000000001",
                       InvalidArgument);
  CHECK_THROWS_AS(refs.session(LiveStopRule{0.5, 0, 0}), InvalidArgument);
  CHECK_THROWS_AS(refs.session(LiveStopRule{0.5, 3, 2}), InvalidArgument);
  // A fusion over a classifier the recogniser lacks; an unfitted recogniser.
  CHECK_THROWS_WITH_AS(LiveSession(refs.recognizer(), Fusion::classifier("iclapn")),
                       doctest::Contains("iclapn"), InvalidArgument);
  Recognizer unfitted(test::paper_classifiers());
  CHECK_THROWS_WITH_AS(LiveSession(unfitted, Fusion::classifier("icp")), doctest::Contains("not fitted"),
                       InvalidArgument);
  // Min-max and z-score normalisation make the confidence meaningless.
  for (const Normalization n : {Normalization::MinMax, Normalization::ZScore})
    CHECK_THROWS_WITH_AS(LiveReferences<>(t, train, test::paper_classifiers, codebook(), Fusion::classifier("icp"), n).session(),
                         doctest::Contains("needs l2 normalisation"), InvalidArgument);
  // References: an object without training touches; an empty factory.
  std::vector<Index> no_ring;
  for (Index i : train)
    if (t.object[static_cast<std::size_t>(i)] != 1) no_ring.push_back(i);
  CHECK_THROWS_WITH_AS(LiveReferences<>(t, no_ring, test::paper_classifiers, codebook(), Fusion::classifier("icp")),
                       "table: object 'ring' has no training touch", InvalidArgument);
  CHECK_THROWS_AS(LiveReferences<>(t, train, ClassifierFactory{}, codebook(), Fusion::classifier("icp")),
                  InvalidArgument);
  CHECK_THROWS_AS(LiveReferences<>(t, {t.size()}, test::paper_classifiers, codebook(), Fusion::classifier("icp")),
                  InvalidArgument);
  // References of one object: a session would be sure of it (confidence 1)
  // after any touch, of anything.
  TouchTable one = t.select(of_object(t, train, 0));
  one.objects.resize(1);
  CHECK_THROWS_WITH_AS(LiveReferences<>(one, {}, test::paper_classifiers, codebook(), Fusion::classifier("icp")),
                       ("table: 1 object ('" + t.objects[0] + "'); recognition needs at least 2 objects to choose among")
                           .c_str(),
                       InvalidArgument);
}

TEST_CASE("live weights: fixed methods pass through, fitted ones come from the grid") {
  // Features are pure noise: BoW cannot tell the objects apart, ICP can.
  const TouchTable t = synthetic_table(4, /*feature_noise=*/3.0);
  CrossValidationSettings s;
  s.touches = {2, 6};
  s.weight_repeats = 2;
  s.threads = 2;
  const Method fixed = parse_method("0.3*icp+0.7*bow");
  const LiveWeights w0 = choose_live_weights(t, test::paper_classifiers, codebook(), fixed, s);
  CHECK(w0.weights.empty());
  CHECK(w0.folds == 0);
  CHECK(w0.fusion.to_string() == "0.3*icp+0.7*bow");

  const Method fitted = parse_method("icp+bow");
  const LiveWeights w = choose_live_weights(t, test::paper_classifiers, codebook(), fitted, s);
  REQUIRE(w.weights.size() == 2);
  CHECK(w.weights[0] + w.weights[1] == doctest::Approx(1.0));
  CHECK(w.weights[0] >= 0.5);  // the informative classifier weighs more
  CHECK(w.folds == 4);
  CHECK(w.total == 4 * 3 * 2 * 2);  // folds x objects x touch counts x draws
  CHECK(w.correct > w.total / 2);
  CHECK(w.fusion.to_string() == fitted.fusion.with_weights(w.weights).to_string());
  // Deterministic, whatever the thread count.
  s.threads = 1;
  CHECK(choose_live_weights(t, test::paper_classifiers, codebook(), fitted, s).weights == w.weights);
  // The chosen vector is the best of the grid: no other fixed weights get
  // more of the same held-out tests right.
  std::vector<Method> grid;
  for (const auto& g : weight_grid(2)) grid.push_back(Method{fitted.fusion.with_weights(g).to_string(),
                                                             fitted.fusion.with_weights(g), false, {}});
  s.repeats = s.weight_repeats;
  s.weight_sweeps = false;
  const CrossValidationResult cv = CrossValidation<>(t, test::paper_classifiers, codebook(), grid, s).run();
  for (const auto& m : cv.methods) {
    CAPTURE(m.name);
    CHECK(m.correct[0] + m.correct[1] <= w.correct);
  }
  // Two explorations per object are enough (no nested search).
  std::vector<Index> keep;
  for (Index i = 0; i < t.size(); ++i)
    if (t.exploration[static_cast<std::size_t>(i)] < 12) keep.push_back(i);
  const TouchTable two = t.select(keep);
  CHECK(choose_live_weights(two, test::paper_classifiers, codebook(), fitted, s).folds == 2);
  // Too few weight steps for the terms are named as CrossValidation names
  // them (it said "steps").
  s.weight_steps = 3;
  CHECK_THROWS_WITH_AS(
      choose_live_weights(t, test::paper_classifiers, codebook(), parse_method("iclap+icp+bow+iclapn"), s),
      doctest::Contains("weight_steps: is 3, fewer than the 4 terms"), InvalidArgument);
}

TEST_CASE("live evaluation: replays held-out explorations in time order, deterministic for any thread count") {
  const TouchTable t = synthetic_table(5);
  LiveEvaluationSettings s;
  s.max_touches = 12;
  s.cross_validation.touches = {1, 4, 12};
  s.cross_validation.repeats = 2;
  s.cross_validation.weight_repeats = 1;
  s.cross_validation.threads = 2;
  const Method method = parse_method("iclap+icp");
  const LiveEvaluationResult r = evaluate_live_stopping(t, test::paper_classifiers, codebook(), method, s);
  CHECK(r.folds == 4);
  REQUIRE(r.traces.size() == 12);
  REQUIRE(r.fold_expressions.size() == 4);
  for (std::size_t f = 0; f < 4; ++f)  // the weights CrossValidation chose for each fold
    CHECK(r.fold_expressions[f] == r.random_draws.methods[0].fold_expressions[f]);
  for (const auto& tr : r.traces) {
    CHECK(tr.available == 20);
    CHECK(tr.replayed() == 12);
    CHECK(tr.confidence.size() == 12);
    CHECK(tr.fused.size() == 12);
    CHECK(tr.exploration == 10 + tr.fold);
  }

  // Trace 0 (fold 0, bar) by hand: its first 12 touches in frame order.
  {
    std::vector<Index> held, train;
    split(t, 10, held, train);
    std::vector<Index> bar = of_object(t, held, 0);
    std::sort(bar.begin(), bar.end(), [&](Index a, Index b) {
      return t.frame[static_cast<std::size_t>(a)] < t.frame[static_cast<std::size_t>(b)];
    });
    const Fusion fold0 = method.fusion.with_weights(r.random_draws.methods[0].fold_weights[0]);
    CHECK(fold0.to_string() == r.fold_expressions[0]);
    const LiveReferences<> refs(t, train, test::paper_classifiers, codebook(), fold0);
    LiveSession sess = refs.session(LiveStopRule{1.0, 1, 0});
    for (std::size_t k = 0; k < 12; ++k) {
      const Index i = bar[k];
      sess.add_touch(t.touches.positions.col(i), t.touches.features.col(i), refs.word(t.touches.features.col(i)));
      CHECK(r.traces[0].best[k] == sess.best());
      CHECK(r.traces[0].confidence[k] == sess.confidence());
    }
  }

  // Stop outcomes read off the traces.
  const LiveStopOutcome at0 = r.stop(LiveStopRule{0.0, 1, 0});
  CHECK(at0.tests == 12);
  CHECK(at0.mean_touches == 1.0);
  CHECK(at0.confident == 12);
  CHECK(at0.correct == r.fixed(1).correct);
  const LiveStopOutcome never = r.stop(LiveStopRule{1.0, 1, 0});
  CHECK(never.mean_touches == 12.0);
  CHECK(never.median_touches == 12.0);
  CHECK(never.confident == 0);
  CHECK(never.correct == r.fixed(12).correct);
  const LiveStopOutcome capped = r.stop(LiveStopRule{1.0, 1, 5});
  CHECK(capped.mean_touches == 5.0);
  CHECK(capped.correct == r.fixed(5).correct);
  const LiveStopOutcome mid = r.stop(LiveStopRule{0.3, 2, 0});
  for (std::size_t k = 0; k < r.traces.size(); ++k) {  // the first touch >= 2 reaching 0.3, else 12
    const auto& c = r.traces[k].confidence;
    Index expect = 12;
    for (Index n = 2; n <= 12; ++n)
      if (c[static_cast<std::size_t>(n - 1)] >= 0.3) {
        expect = n;
        break;
      }
    CHECK(mid.touches[k] == expect);
  }
  CHECK(r.fixed(12).accuracy() > 0.9);
  // A trace shorter than min_touches stops at its end, not confident (it
  // was read at its last touch and counted confident).
  {
    LiveEvaluationResult shorter = r;
    for (auto& tr : shorter.traces) {
      tr.best.resize(2);
      tr.confidence.assign(2, 0.9);
      tr.fused.resize(2);
    }
    const LiveStopOutcome o = shorter.stop(LiveStopRule{0.5, 5, 0});
    CHECK(o.confident == 0);
    for (const Index n : o.touches) CHECK(n == 2);
    CHECK(shorter.stop(LiveStopRule{0.5, 2, 0}).confident == 12);
  }
  CHECK_THROWS_AS(r.stop(LiveStopRule{0.5, 1, 13}), InvalidArgument);
  CHECK_THROWS_AS(r.fixed(0), InvalidArgument);
  CHECK_THROWS_AS(r.fixed(13), InvalidArgument);

  s.cross_validation.threads = 1;
  const LiveEvaluationResult r1 = evaluate_live_stopping(t, test::paper_classifiers, codebook(), method, s);
  REQUIRE(r1.traces.size() == r.traces.size());
  for (std::size_t k = 0; k < r.traces.size(); ++k) {
    CHECK(r1.traces[k].best == r.traces[k].best);
    CHECK(r1.traces[k].confidence == r.traces[k].confidence);
  }
  CHECK(r1.fold_expressions == r.fold_expressions);

  s.max_touches = 0;
  CHECK_THROWS_AS(evaluate_live_stopping(t, test::paper_classifiers, codebook(), method, s), InvalidArgument);
  // A normalisation live sessions refuse is refused before any run (it
  // was refused by the first replay, after the whole cross validation).
  s.max_touches = 4;
  s.cross_validation.normalization = Normalization::MinMax;
  int ran = 0;
  CHECK_THROWS_WITH_AS(evaluate_live_stopping(t, test::paper_classifiers, codebook(), method, s,
                                              [&](std::size_t, std::size_t) { ++ran; }),
                       doctest::Contains("cross_validation.normalization: live recognition needs l2"), InvalidArgument);
  CHECK(ran == 0);
  s.cross_validation.normalization = Normalization::L2;
  // Fitted weights need inner folds: 3 explorations of every object.
  s.max_touches = 4;
  std::vector<Index> keep;
  for (Index i = 0; i < t.size(); ++i)
    if (t.exploration[static_cast<std::size_t>(i)] < 12 || t.object[static_cast<std::size_t>(i)] != 2) keep.push_back(i);
  const TouchTable two = t.select(keep);
  CHECK_THROWS_WITH_AS(evaluate_live_stopping(two, test::paper_classifiers, codebook(), method, s),
                       doctest::Contains("'bar_hooked' has 2"), InvalidArgument);
  CHECK(evaluate_live_stopping(two, test::paper_classifiers, codebook(), parse_method("0.5*iclap+0.5*icp"), s).folds == 2);
}

TEST_CASE("live session: bad stop rules, vocabularies, words and points are refused under their own names") {
  // A negative limit is not "no limit"; a limit equal to min_touches is allowed.
  CHECK_THROWS_WITH_AS((LiveStopRule{0.5, 1, -1}.validate()),
                       "max_touches: must be 0 (no limit) or >= min_touches (1), got -1", InvalidArgument);
  CHECK_NOTHROW((LiveStopRule{0.5, 3, 3}.validate()));

  const TouchTable t = oriented_table(6);
  std::vector<Index> held, train;
  split(t, 11, held, train);
  // Only bow is fused: the pad orientation is optional for it, so the
  // session's own checks are all that refuse a mixed or broken touch.
  const LiveReferences<> refs(t, train, oriented_classifiers, codebook(), Fusion::classifier("bow"));
  CHECK_THROWS_WITH_AS(LiveSession(refs.recognizer(), refs.fusion(), LiveStopRule{}, -1),
                       "vocabulary: must be >= 0, got -1", InvalidArgument);
  LiveSession s = refs.session();
  const Index i = held.front();
  LiveTouch bare = live_touch_of(t.touches, i, 0);
  bare.normal.reset();
  LiveTouch negative_word = bare;
  negative_word.word = -1;
  CHECK_THROWS_WITH_AS(s.add_touch(negative_word), "word: -1 is outside [0, 4)", InvalidArgument);
  s.add_touch(bare);
  CHECK_THROWS_WITH_AS(s.add_touch(live_touch_of(t.touches, i, 0)),
                       "normal: touch 2 has a pad normal but the earlier touches have none", InvalidArgument);
  CHECK(s.touches() == 1);

  LiveSession oriented = refs.session();
  LiveTouch nan_contact = live_touch_of(t.touches, i, 0);
  nan_contact.contact_points(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK(test::argument_of([&] { oriented.add_touch(nan_contact); }) == "contact_points");
  LiveTouch nan_free = live_touch_of(t.touches, i, 0);
  nan_free.free_points = Eigen::Matrix3Xd::Zero(3, 2);
  nan_free.free_points(0, 1) = std::numeric_limits<double>::infinity();
  CHECK(test::argument_of([&] { oriented.add_touch(nan_free); }) == "free_points");
  CHECK(oriented.touches() == 0);

  // The references' word() and construction name what is wrong.
  CHECK(test::argument_of([&] { (void)refs.word(Eigen::Vector3f(1, 0, 0)); }) == "feature");
  CHECK_THROWS_WITH_AS(refs.word(Eigen::Vector4f(0, std::numeric_limits<float>::quiet_NaN(), 0, 0)),
                       doctest::Contains("feature: "), NonFiniteValue);
  CHECK_THROWS_WITH_AS(LiveReferences<>(t, {-1}, oriented_classifiers, codebook(), Fusion::classifier("bow")),
                       "train: touch -1 is outside [0, 240)", InvalidArgument);
  // A touch listed twice would weigh twice in the codebook and its reference.
  CHECK_THROWS_WITH_AS(LiveReferences<>(t, {0, 1, 2, 1}, oriented_classifiers, codebook(), Fusion::classifier("bow")),
                       "train: touch 1 is listed twice", InvalidArgument);
  TouchTable empty;
  empty.objects = {"bar"};
  CHECK_THROWS_WITH_AS(LiveReferences<>(empty, {}, oriented_classifiers, codebook(), Fusion::classifier("bow")),
                       "table: holds no touch", EmptyInput);
  // No training indices: every touch of the table.
  CHECK(LiveReferences<>(t, {}, oriented_classifiers, codebook(), Fusion::classifier("bow")).touches_per_object() ==
        std::vector<Index>{80, 80, 80});
}

TEST_CASE("live session: history, a confident stop at the limit, and a reset that forgets everything") {
  const TouchTable t = synthetic_table(7);
  std::vector<Index> held, train;
  split(t, 12, held, train);
  const LiveReferences<> refs(t, train, test::paper_classifiers, codebook(), parse_method("0.5*icp+0.5*bow").fusion);
  const auto test = of_object(t, held, 2);
  // Confident (threshold 0) and at the limit on touch 2: the confident stop wins.
  LiveSession s = refs.session(LiveStopRule{0.0, 2, 2});
  std::vector<double> confidences;
  for (std::size_t k = 0; k < 2; ++k) {
    const Index i = test[k];
    const LiveStop stop =
        s.add_touch(t.touches.positions.col(i), t.touches.features.col(i), refs.word(t.touches.features.col(i)));
    CHECK(stop == (k == 0 ? LiveStop::kContinue : LiveStop::kConfident));
    confidences.push_back(s.confidence());
  }
  REQUIRE(s.history().size() == 2);
  for (std::size_t k = 0; k < 2; ++k) CHECK(s.history()[k].confidence == confidences[k]);
  REQUIRE(s.confidence() > 0);
  s.reset();
  CHECK(s.confidence() == 0.0);
  CHECK(s.fused().size() == 0);
  CHECK(s.distances().objects() == 0);
  CHECK(s.ranking().empty());
  CHECK(s.stop() == LiveStop::kContinue);
}

TEST_CASE("rank_objects: best first, ties in index order, for any number of objects") {
  CHECK(rank_objects(Eigen::Vector4d(1, 0, 1, 0)) == std::vector<Index>{1, 3, 0, 2});
  // Enough objects that an unstable sort would reorder ties.
  const Index n = 60;
  Eigen::VectorXd fused(n);
  for (Index i = 0; i < n; ++i) fused(i) = static_cast<double>((i * 7) % 3);
  std::vector<Index> expected;
  for (int value = 0; value < 3; ++value)
    for (Index i = 0; i < n; ++i)
      if (fused(i) == static_cast<double>(value)) expected.push_back(i);
  CHECK(rank_objects(fused) == expected);
}

TEST_CASE("live weights: a tie goes to the earlier grid vector; a method with alternatives is refused") {
  // Bar and ring only: every weight vector recognises every test.
  const TouchTable three = synthetic_table(8);
  std::vector<Index> rows;
  for (Index i = 0; i < three.size(); ++i)
    if (three.object[static_cast<std::size_t>(i)] != 2) rows.push_back(i);
  TouchTable t = three.select(rows);
  t.objects.pop_back();
  CrossValidationSettings s;
  s.touches = {3};
  s.weight_repeats = 1;
  const Method fitted = parse_method("icp+bow");
  const LiveWeights w = choose_live_weights(t, test::paper_classifiers, codebook(), fitted, s);
  REQUIRE(w.total > 0);
  REQUIRE(w.correct == w.total);
  CHECK(w.weights == weight_grid(2).front());

  Method with_alternative = fitted;
  with_alternative.alternatives = {parse_method("iclap+bow").fusion};
  CHECK_THROWS_WITH_AS(choose_live_weights(t, test::paper_classifiers, codebook(), with_alternative, s),
                       doctest::Contains("method: 'icp+bow' has alternatives"), InvalidArgument);
}

TEST_CASE("live evaluation: stop rules and fixed counts read off hand-made traces") {
  LiveEvaluationResult r;
  r.max_touches = 4;
  auto trace = [](Index object, std::vector<Index> best, std::vector<double> confidence) {
    LiveTrace tr;
    tr.object = object;
    tr.best = std::move(best);
    tr.confidence = std::move(confidence);
    tr.available = tr.replayed();
    return tr;
  };
  r.traces = {trace(0, {1, 0, 0, 0}, {0.2, 0.5, 0.9, 0.9}), trace(1, {1, 1, 0}, {0.1, 0.3, 0.5}),
              trace(2, {2, 2, 2, 2}, {0.5, 0.5, 0.5, 0.5}), trace(0, {0, 0, 0, 0}, {0.1, 0.1, 0.1, 0.1})};
  // A confidence equal to the threshold stops.
  const LiveStopOutcome o = r.stop(LiveStopRule{0.5, 1, 0});
  CHECK(o.touches == std::vector<Index>{2, 3, 1, 4});
  CHECK(o.tests == 4);
  CHECK(o.confident == 3);
  CHECK(o.correct == 3);
  CHECK(o.mean_touches == 2.5);
  CHECK(o.median_touches == 2.5);  // the mean of the two middle ones
  // A limit equal to the touches replayed is allowed.
  const LiveStopOutcome at_limit = r.stop(LiveStopRule{1.0, 1, 4});
  CHECK(at_limit.touches == std::vector<Index>{4, 3, 4, 4});
  CHECK(at_limit.confident == 0);
  const LiveFixedOutcome four = r.fixed(4);
  CHECK(four.tests == 4);
  CHECK(four.short_tests == 1);
  CHECK(four.correct == 3);
  CHECK(r.fixed(1).short_tests == 0);
  CHECK(r.fixed(1).correct == 3);
}

TEST_CASE("live_touch_of: a touch of a set brings its own contact and free points, only with a normal") {
  TouchSet s;
  s.positions = Eigen::Matrix3Xd::Zero(3, 2);
  s.contact_points = Eigen::Matrix3Xd::Random(3, 5);
  s.contact_offsets = {0, 1, 5};
  s.free_points = Eigen::Matrix3Xd::Random(3, 4);
  s.free_offsets = {0, 3, 4};
  // Without normals the orientation is unknown: no points either.
  CHECK(live_touch_of(s, 1, 0).contact_points.cols() == 0);
  s.normals = Eigen::Matrix3Xd::Zero(3, 2);
  s.normals.row(2).setConstant(-1);
  const LiveTouch second = live_touch_of(s, 1, 0);
  CHECK(second.contact_points == s.contact_points.rightCols(4));
  CHECK(second.free_points == s.free_points.rightCols(1));
  CHECK_THROWS_WITH_AS(live_touch_of(s, -1, 0), "i: touch -1 is outside [0, 2)", InvalidArgument);
}

namespace {

/// A custom quantizer that checks nothing itself: word 1 when the first value is positive.
struct SignQuantizer {
  void fit(const Eigen::MatrixXf&) {}
  Index assign(const Eigen::Ref<const Eigen::VectorXf>& feature) const { return feature(0) > 0 ? 1 : 0; }
  Index size() const { return 2; }
};

}  // namespace

TEST_CASE("live references: word() checks the descriptor itself, whatever the quantizer") {
  const TouchTable t = synthetic_table(9);
  const LiveReferences<SignQuantizer> refs(t, {}, test::paper_classifiers, SignQuantizer{}, Fusion::classifier("icp"));
  CHECK(refs.word(Eigen::Vector4f(1, 0, 0, 0)) == 1);
  CHECK_THROWS_WITH_AS(refs.word(Eigen::Vector3f(1, 0, 0)), doctest::Contains("feature: "), DimensionMismatch);
  CHECK_THROWS_WITH_AS(refs.word(Eigen::Vector4f(1, std::numeric_limits<float>::quiet_NaN(), 0, 0)),
                       doctest::Contains("feature: "), NonFiniteValue);
}
