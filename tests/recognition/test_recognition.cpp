// SPDX-License-Identifier: MIT
// Classifiers, the recogniser and the cross-validation engine on small
// synthetic touch data.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/recognition/recognition.hpp"
#include "../support/errors.hpp"
#include "synthetic_objects.hpp"

using namespace iclap;

namespace {

using test::synthetic_table;  // 25 touches per exploration, in time order

/// The paper's three and positions-plus-descriptor iCLAP.
std::vector<std::unique_ptr<Classifier>> all_classifiers() {
  auto cs = test::paper_classifiers();
  cs.push_back(std::make_unique<IclapNClassifier<4, double, SpatialRigid>>());
  return cs;
}

KMeansQuantizer<float> codebook(Index k) {
  KMeansQuantizer<float> q;
  q.settings.k = k;
  q.settings.seed = 3;
  return q;
}

/// Training sets per object from the whole table, with words.
std::vector<TouchSet> per_object(const TouchTable& t, const WordIds& words) {
  TouchSet all = t.touches;
  all.words = words;
  std::vector<TouchSet> out;
  for (Index o = 0; o < 3; ++o) {
    std::vector<Index> idx;
    for (Index i = 0; i < t.size(); ++i)
      if (t.object[static_cast<std::size_t>(i)] == o) idx.push_back(i);
    out.push_back(select_touches(all, idx));
  }
  return out;
}

/// "ARGUMENT | REASON" of the InvalidArgument `f` throws.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return std::string(e.argument()) + " | " + e.reason();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("each classifier recognises tests drawn from its own training data") {
  const TouchTable t = synthetic_table(1);
  KMeansQuantizer<float> q = codebook(4);
  q.fit(t.touches.features);
  const WordIds words = assign_words(q, t.touches.features);
  const auto objects = per_object(t, words);
  for (auto& c : all_classifiers()) {
    c->fit(objects, q.size());
    CHECK(c->objects() == 3);
    for (Index o = 0; o < 3; ++o) {
      // 12 of the object's own training touches.
      std::vector<Index> idx;
      for (Index i = 0; i < 12; ++i) idx.push_back(i * 7 % objects[static_cast<std::size_t>(o)].size());
      const TouchSet test = select_touches(objects[static_cast<std::size_t>(o)], idx);
      Eigen::VectorXd d(3);
      c->distances(test, d);
      CAPTURE(c->name());
      CAPTURE(o);
      CHECK(d.allFinite());
      CHECK(d.minCoeff() >= 0);
      CHECK(decide(d) == o);
      if (c->name() != "bow") CHECK(d(o) < 1e-9);  // every test point is a reference point
    }
  }
}

TEST_CASE("classifier inputs are validated") {
  const TouchTable t = synthetic_table(2);
  BowClassifier bow;
  CHECK_THROWS_AS(bow.fit({}, 4), EmptyInput);
  TouchSet no_words;
  no_words.positions = Eigen::Matrix3Xd::Zero(3, 2);
  CHECK_THROWS_AS(bow.fit({no_words}, 4), EmptyInput);
  TouchSet one_word = no_words;
  one_word.words = WordIds::Zero(2);
  // (A negative vocabulary reached Eigen's size assertion, an abort.)
  CHECK(error_of([&] { bow.fit({one_word}, -1); }).find("vocabulary | ") == 0);
  CHECK(error_of([&] { bow.fit({one_word}, 0); }).find("vocabulary | ") == 0);
  // A word id outside the vocabulary names whose words hold it (it said
  // only "words").
  TouchSet beyond = one_word;
  beyond.words(1) = 4;
  CHECK(error_of([&] { bow.fit({one_word, beyond}, 4); }).find("objects[1].words | word 4 at position 1") == 0);
  bow.fit({one_word, one_word}, 4);
  Eigen::VectorXd bow_out(2);
  CHECK(error_of([&] { bow.distances(beyond, bow_out); }).find("test.words | word 4 at position 1") == 0);
  IcpClassifier<double> icp;
  TouchSet bad = no_words;
  bad.positions(1, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(icp.fit({bad}, 4), NonFiniteValue);
  IclapNClassifier<4> fixed;
  TouchSet wrong = no_words;
  wrong.features = Eigen::MatrixXf::Zero(5, 2);  // 5-D features for a 4-D classifier
  CHECK_THROWS_AS(fixed.fit({wrong}, 4), DimensionMismatch);
  IclapClassifier<float> iclap;
  iclap.embedding.label_scale = -1;
  TouchSet labeled = no_words;
  labeled.words = WordIds::Zero(2);
  CHECK_THROWS_AS(iclap.fit({labeled}, 4), InvalidArgument);
}

TEST_CASE("touch coordinates beyond the registration's scalar range are refused, naming the touch") {
  // 1e300 m (a unit error) became inf in a float cloud and failed inside the
  // registration as "test: non-finite value inf at row 0, column 5".
  const TouchTable t = synthetic_table(1);
  KMeansQuantizer<float> q = codebook(4);
  q.fit(t.touches.features);
  const auto objects = per_object(t, assign_words(q, t.touches.features));
  auto far = objects;
  far[1].positions(2, 5) = 1e300;
  IclapClassifier<float> fc;
  const std::string fit_error = error_of([&] { fc.fit(far, q.size()); });
  CHECK_MESSAGE(fit_error.find("objects[1].positions | ") == 0, fit_error);
  CHECK_MESSAGE(fit_error.find("touch 5: coordinate 1e+300 is beyond the float registration's range (|v| <= "
                               "1.84467e+15)") != std::string::npos,
                fit_error);
  CHECK(fc.objects() == 0);  // nothing fitted

  fc.fit(objects, q.size());
  IclapClassifier<double> dc;
  dc.fit(objects, q.size());
  TouchSet test = select_touches(objects[0], std::vector<Index>{0, 1, 2, 3});
  test.positions(0, 2) = -2e15;  // beyond float's range, within double's
  Eigen::VectorXd d(3);
  for (const std::string& e : {error_of([&] { fc.distances(test, d); }),
                               error_of([&] { (void)fc.decide(test); }),
                               error_of([&] { (void)fc.lower_bounds(test); }),
                               error_of([&] { (void)fc.register_against(test, 1); })}) {
    CHECK_MESSAGE(e.find("test.positions | ") == 0, e);
    CHECK_MESSAGE(e.find("touch 2: coordinate -2e+15") != std::string::npos, e);
  }
  const std::string pool_error = error_of([&] { (void)fc.prepare_pool(test); });
  CHECK_MESSAGE(pool_error.find("pool.positions | ") == 0, pool_error);
  dc.distances(test, d);
  CHECK(d.allFinite());
  test.positions(1, 3) = 1e151;  // beyond double's range too
  const std::string double_error = error_of([&] { dc.distances(test, d); });
  CHECK_MESSAGE(double_error.find("test.positions | touch 3: coordinate 1e+151 is beyond the double") == 0,
                double_error);

  // A descriptor the float cloud cannot hold names the embedded point.
  IclapNClassifier<4, float> fn;
  fn.fit(objects, q.size());
  TouchSet loud = select_touches(objects[2], std::vector<Index>{0, 1, 2});
  loud.features(3, 1) = 3e38f;
  const std::string feature_error = error_of([&] { fn.distances(loud, d); });
  CHECK_MESSAGE(feature_error ==
                    "test | value 3e+38 at row 6, column 1 is beyond the float range of distances (|v| <= "
                    "1.84467e+15): squared distances would overflow; rescale",
                feature_error);
}

TEST_CASE("a touch table's rows are selected with their object, exploration and frame") {
  const TouchTable t = synthetic_table(3);
  REQUIRE(t.size() > 40);
  const std::vector<Index> rows = {40, 2, 2, t.size() - 1};
  const TouchTable s = t.select(rows);
  REQUIRE(s.size() == 4);
  CHECK(s.objects == t.objects);
  CHECK(s.idle_frames == 0);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto r = static_cast<std::size_t>(rows[k]);
    CHECK(s.object[k] == t.object[r]);
    CHECK(s.exploration[k] == t.exploration[r]);
    CHECK(s.frame[k] == t.frame[r]);
    CHECK(s.touches.positions.col(static_cast<Index>(k)) == t.touches.positions.col(rows[k]));
    CHECK(s.touches.features.col(static_cast<Index>(k)) == t.touches.features.col(rows[k]));
  }
  CHECK(t.select({}).size() == 0);
  CHECK_THROWS_WITH_AS(t.select({0, t.size()}), doctest::Contains("position 1"), InvalidArgument);
  CHECK_THROWS_WITH_AS(t.select({-1}), doctest::Contains("rows"), InvalidArgument);
}

TEST_CASE("the recogniser fuses every classifier once per test") {
  const TouchTable t = synthetic_table(3);
  KMeansQuantizer<float> q = codebook(4);
  q.fit(t.touches.features);
  const auto objects = per_object(t, assign_words(q, t.touches.features));
  Recognizer rec(all_classifiers());
  rec.check(paper_methods());
  rec.fit(objects, q.size());
  const DistanceTable table = rec.distances(objects[1]);
  for (const char* name : {"bow", "icp", "iclap", "iclapn"}) {
    CHECK(table.get(name).norm() == doctest::Approx(1.0));  // L2-normalised
  }
  for (const auto& m : paper_methods()) CHECK(decide(m.fusion.evaluate(table)) == 1);
  const DistanceTable only = rec.distances(objects[0], {"icp"});
  CHECK(only.has("icp"));
  CHECK(!only.has("bow"));
}

namespace {
// A classifier of a user's own whose distances are `value` for every object.
struct ConstantClassifier final : Classifier {
  explicit ConstantClassifier(double v) : value(v) {}
  double value;
  Index n = 0;
  std::string name() const override { return "mine"; }
  void fit(const std::vector<TouchSet>& objects, Index) override { n = static_cast<Index>(objects.size()); }
  void distances(const TouchSet&, Eigen::Ref<Eigen::VectorXd> out) const override { out.setConstant(value); }
  Index objects() const override { return n; }
};
}  // namespace

TEST_CASE("the recogniser names the classifier whose distances are bad, and refuses an unknown name in only") {
  const TouchTable t = synthetic_table(3);
  KMeansQuantizer<float> q = codebook(4);
  q.fit(t.touches.features);
  const auto objects = per_object(t, assign_words(q, t.touches.features));
  const auto recognizer = [&](double value, Normalization kind) {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<BowClassifier>());
    cs.push_back(std::make_unique<ConstantClassifier>(value));
    Recognizer rec(std::move(cs), kind);
    rec.fit(objects, q.size());
    return rec;
  };
  CHECK(recognizer(2.0, Normalization::L2).distances(objects[0]).get("mine").norm() == doctest::Approx(1.0));
  CHECK(test::what_of<NonFiniteValue>([&] {
          (void)recognizer(std::numeric_limits<double>::quiet_NaN(), Normalization::L2).distances(objects[0]);
        }).find("distances of 'mine': ") == 0);
  for (const auto kind : {Normalization::L2, Normalization::MinMax}) {
    CAPTURE(to_string(kind));
    CHECK(test::what_of([&] { (void)recognizer(-1.0, kind).distances(objects[0]); })
              .find("distances of 'mine': must be non-negative") == 0);
  }
  CHECK(test::what_of([&] { (void)recognizer(-1.0, Normalization::ZScore).distances(objects[0]); }) == "(no error)");

  const Recognizer rec = recognizer(2.0, Normalization::L2);
  CHECK(test::what_of([&] { (void)rec.distances(objects[0], {"bow", "icp"}); }) ==
        "only: 'icp' is not the name of a classifier (bow, mine)");
  CHECK(test::argument_of([&] { (void)rec.prepare_pool(objects[0], {"typo"}); }) == "only");
  CHECK(test::argument_of([&] { (void)rec.pool_distances(objects[0], rec.prepare_pool(objects[0]), {0}, {"typo"}); }) ==
        "only");
  CHECK(rec.distances(objects[0], {"mine"}).has("mine"));
}

TEST_CASE("a prepared pool gives each subset the recogniser's distances of its own touches") {
  const TouchTable t = synthetic_table(3);
  KMeansQuantizer<float> q = codebook(4);
  q.fit(t.touches.features);
  const WordIds words = assign_words(q, t.touches.features);
  Recognizer rec(all_classifiers());
  rec.fit(per_object(t, words), q.size());
  TouchSet pool = t.touches;
  pool.words = words;
  std::vector<double> seconds;
  const auto prepared = rec.prepare_pool(pool, {}, &seconds, 2);
  REQUIRE(prepared.size() == 4);
  CHECK(prepared[0] == nullptr);  // bow: nothing to reuse
  for (std::size_t i = 1; i < 4; ++i) CHECK(prepared[i] != nullptr);  // icp, iclap, iclapn
  CHECK(seconds.size() == 4);
  Rng rng(5);
  for (Index n : {1, 4, 9, 25}) {
    for (int draw = 0; draw < 3; ++draw) {
      std::vector<Index> subset;
      for (Index k = 0; k < n; ++k)
      subset.push_back(static_cast<Index>(rng.below(static_cast<std::uint64_t>(pool.size()))));
      const DistanceTable a = rec.pool_distances(pool, prepared, subset);
      const DistanceTable b = rec.distances(select_touches(pool, subset));
      for (const char* name : {"bow", "icp", "iclap", "iclapn"}) {
        CAPTURE(name);
        CAPTURE(n);
        CHECK(a.get(name) == b.get(name));  // bit for bit
      }
    }
  }
  const auto icp_only = rec.prepare_pool(pool, {"icp"});
  CHECK(icp_only[1] != nullptr);
  CHECK(icp_only[2] == nullptr);
  const std::vector<Index> pair = {0, 1};
  CHECK(rec.pool_distances(pool, icp_only, pair).get("iclap") == rec.distances(select_touches(pool, pair)).get("iclap"));
  CHECK_THROWS_AS(rec.pool_distances(pool, {prepared[0]}, {0}), DimensionMismatch);
  try {
    rec.pool_distances(pool, prepared, {0, pool.size()});
    FAIL("a subset index outside the pool was accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "subset");
    CHECK(std::string(e.what()).find("entry 1") != std::string::npos);
  }
}

TEST_CASE("cross validation: rates, weights from training folds, identical for any thread count") {
  const TouchTable t = synthetic_table(4);
  CrossValidationSettings s;
  s.touches = {1, 3, 8};
  s.repeats = 4;
  s.weight_repeats = 1;
  s.seed = 9;
  auto methods = paper_methods();
  methods.push_back(parse_method("0.5*iclapn+0.5*bow"));
  s.threads = 1;
  CrossValidation<> one(t, all_classifiers, codebook(4), methods, s);
  CHECK(one.folds() == 4);
  const auto a = one.run();
  s.threads = 2;
  CrossValidation<> two(t, all_classifiers, codebook(4), methods, s);
  std::size_t last = 0, calls = 0;
  const auto b = two.run([&](std::size_t done, std::size_t total) {
    CHECK(total > 0);
    CHECK(done <= total);
    last = done;
    ++calls;
  });
  CHECK(calls > 0);
  CHECK(last == calls);  // every test set reported once
  REQUIRE(a.methods.size() == methods.size());
  CHECK(a.vocabulary == std::vector<Index>{4, 4, 4, 4});
  for (std::size_t m = 0; m < methods.size(); ++m) {
    CAPTURE(methods[m].name);
    CHECK(a.methods[m].correct == b.methods[m].correct);
    CHECK(a.methods[m].fold_weights == b.methods[m].fold_weights);
    for (std::size_t i = 0; i < s.touches.size(); ++i) {
      CHECK(a.methods[m].total[i] == 3 * 4 * 4);  // objects x folds x repeats
      CHECK(a.methods[m].rate(i) >= 0.0);
      CHECK(a.methods[m].rate(i) <= 1.0);
      CHECK(a.methods[m].confusion[i].sum() == a.methods[m].total[i]);
      CHECK(a.methods[m].confusion[i].diagonal().sum() == a.methods[m].correct[i]);
    }
    if (methods[m].fit_weights) {
      REQUIRE(a.methods[m].fold_weights.size() == 4);
      for (const auto& w : a.methods[m].fold_weights) {
        double sum = 0;
        for (double x : w) sum += x;
        CHECK(sum == doctest::Approx(1.0));
      }
    } else {
      CHECK(a.methods[m].fold_weights[0].empty());
    }
  }
  // On these easy objects the fused methods recognise nearly everything at 8 touches.
  CHECK(a.methods[9].rate(2) > 0.9);
  // Weight sweeps exist for every fitted method and count every test.
  CHECK(a.sweeps.size() == 4);  // icp+bow, iclap+icp, iclap+bow, iclap+icp+bow
  for (const auto& sw : a.sweeps) {
    CHECK(sw.correct.size() == sw.grid.size());
    CHECK(sw.total[0] == 48);
  }
}

// A classifier that cannot tell objects apart: every distance is 1.
struct Blind final : Classifier {
  std::string label;
  Index n = 0;
  explicit Blind(std::string name) : label(std::move(name)) {}
  std::string name() const override { return label; }
  void fit(const std::vector<TouchSet>& objects, Index) override { n = static_cast<Index>(objects.size()); }
  void distances(const TouchSet&, Eigen::Ref<Eigen::VectorXd> out) const override { out.setOnes(); }
  Index objects() const override { return n; }
};

TEST_CASE("cross validation chooses among a method's alternatives on the training folds") {
  const TouchTable t = synthetic_table(4);
  auto factory = [] {
    auto cs = test::paper_classifiers();  // bow, icp, iclap
    cs.push_back(std::make_unique<Blind>("blind"));
    auto trimmed = std::make_unique<IcpClassifier<float, Planar>>();
    trimmed->label = "icp_trim";
    trimmed->icp.rejection.trim_fraction = 0.5f;
    cs.push_back(std::move(trimmed));
    return cs;
  };
  CrossValidationSettings s;
  s.touches = {1, 3, 8};
  s.repeats = 3;
  s.weight_repeats = 1;
  s.threads = 2;
  // The blind candidate comes first, so choosing it would be the default.
  Method single{"blind-or-iclap", Fusion::classifier("blind"), false, {Fusion::classifier("iclap")}};
  Method fitted = with_variants(parse_method("icp+bow"), "icp", {"icp", "icp_trim"});
  fitted.name = "icp-or-trim+bow";  // not "icp+bow", which is also run, alone
  const std::vector<Method> methods = {single, parse_method("iclap"), fitted, parse_method("icp+bow"),
                                       parse_method("icp_trim+bow")};
  const auto r = CrossValidation<>(t, factory, codebook(4), methods, s).run();
  REQUIRE(r.methods.size() == 5);
  // The informative candidate wins in every fold, and the method then
  // recognises exactly as the method written with it alone.
  CHECK(r.methods[0].fold_candidates == std::vector<std::size_t>(4, 1));
  CHECK(r.methods[0].correct == r.methods[1].correct);
  CHECK(r.methods[0].fold_expressions == r.methods[1].fold_expressions);
  CHECK(r.methods[0].confusion[2] == r.methods[1].confusion[2]);
  CHECK(r.methods[1].fold_candidates == std::vector<std::size_t>(4, 0));
  // With fitted weights, each fold's candidate gets its weights chosen as the
  // method written with that candidate alone does, and recognises as it.
  for (std::size_t f = 0; f < 4; ++f) {
    CAPTURE(f);
    const std::size_t c = r.methods[2].fold_candidates.at(f);
    REQUIRE(c < 2);
    const MethodResult& alone = r.methods[3 + c];
    CHECK(r.methods[2].fold_expressions[f] == alone.fold_expressions[f]);
    CHECK(r.methods[2].fold_weights[f] == alone.fold_weights[f]);
    CHECK(r.methods[2].fold_correct[f] == alone.fold_correct[f]);
  }
  // Only the plain fitted methods have a weight sweep.
  REQUIRE(r.sweeps.size() == 2);
  CHECK(r.sweeps[0].method == "icp+bow");
  CHECK(r.sweeps[1].method == "icp_trim+bow");
  // The blind classifier was computed on the inner folds only, never on a test.
  REQUIRE(r.classifiers == std::vector<std::string>{"bow", "icp", "iclap", "blind", "icp_trim"});
  CHECK(r.classifier_tests == std::vector<std::size_t>{r.tests, r.tests, r.tests, 0, r.tests});
  CHECK(r.classifier_seconds[3] == 0.0);
  CHECK(r.tests == 4 * 3 * 3 * 3);  // folds x objects x touch counts x repeats

  // Zero weights (beyond the paper): a fitted sum can drop the blind term,
  // which the paper's grid keeps at 0.1 at least. A constant term never
  // changes a decision but shrinks the margin, so weight 0 wins the tie.
  const std::vector<Method> blind_sum = {parse_method("blind+iclap"), parse_method("iclap")};
  const auto with_floor = CrossValidation<>(t, factory, codebook(4), blind_sum, s).run();
  s.zero_weights = true;
  const auto zero = CrossValidation<>(t, factory, codebook(4), blind_sum, s).run();
  for (std::size_t f = 0; f < 4; ++f) {
    CHECK(with_floor.methods[0].fold_weights[f] == std::vector<double>{0.1, 0.9});
    CHECK(zero.methods[0].fold_weights[f] == std::vector<double>{0.0, 1.0});
  }
  CHECK(zero.methods[0].correct == zero.methods[1].correct);
  CHECK(zero.sweeps.at(0).grid.size() == 11);
  s.zero_weights = false;

  // An alternative that cannot take the method's fitted weights is refused.
  Method bad = parse_method("icp+bow");
  bad.alternatives.push_back(Fusion::classifier("blind"));
  CHECK_THROWS_WITH_AS(CrossValidation<>(t, factory, codebook(4), {bad}, s),
                       "methods: method 'icp+bow' fits weights, but its alternative blind is not a weighted sum of 2 "
                       "terms",
                       InvalidArgument);
  // ... as is an alternative whose classifier the factory does not make.
  Method unknown{"icp", Fusion::classifier("icp"), false, {Fusion::classifier("patch")}};
  CHECK_THROWS_WITH_AS(CrossValidation<>(t, factory, codebook(4), {unknown}, s),
                       "methods: method 'icp' needs classifier 'patch', which is not among the classifiers (bow, "
                       "icp, iclap, blind, icp_trim)",
                       InvalidArgument);
}

// BoW that fails on every test set of exactly 3 touches.
struct FailingBow final : Classifier {
  BowClassifier bow;
  std::string name() const override { return bow.name(); }
  void fit(const std::vector<TouchSet>& objects, Index vocabulary) override { bow.fit(objects, vocabulary); }
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    if (test.size() == 3) throw InvalidArgument("test", "3 touches refused");
    bow.distances(test, out);
  }
  Index objects() const override { return bow.objects(); }
};

TEST_CASE("cross validation passes a classifier's error on, with any number of threads") {
  const TouchTable t = synthetic_table(5);
  auto failing = [] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<FailingBow>());
    return cs;
  };
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    CrossValidationSettings s;
    s.touches = {1, 3};
    s.repeats = 2;
    s.threads = threads;
    CrossValidation<> cv(t, failing, codebook(4), {parse_method("bow")}, s);
    CHECK_THROWS_WITH_AS(cv.run(), "test: 3 touches refused", InvalidArgument);
    s.touches = {1, 2};  // never 3 touches: runs to the end
    CrossValidation<> fine(t, failing, codebook(4), {parse_method("bow")}, s);
    CHECK(fine.run().methods.at(0).total.at(0) > 0);
  }
}

TEST_CASE("cross validation refuses what it cannot do") {
  TouchTable t = synthetic_table(5);
  // A method that needs a classifier the factory does not make.
  auto only_bow = [] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<BowClassifier>());
    return cs;
  };
  CHECK_THROWS_WITH_AS(CrossValidation<>(t, only_bow, codebook(4), {parse_method("icp+bow")}),
                       "methods: method 'icp+bow' needs classifier 'icp', which is not among the classifiers (bow)",
                       InvalidArgument);
  // An object with one exploration cannot be cross-validated.
  for (std::size_t i = 0; i < t.object.size(); ++i)
    if (t.object[i] == 1) t.exploration[i] = 10;
  CHECK_THROWS_WITH_AS(CrossValidation<>(t, only_bow, codebook(4), {parse_method("bow")}),
                       "table: object 'ring' has 1 exploration with touches; cross validation needs at least 2",
                       InvalidArgument);
  CrossValidationSettings s;
  s.touches = {0};
  const TouchTable five = synthetic_table(5);
  CHECK_THROWS_AS(CrossValidation<>(five, only_bow, codebook(4), {parse_method("bow")}, s),
                  InvalidArgument);

  // A grid without a vector for a method's terms is refused at construction
  // naming the setting (run() threw "steps: ..." before).
  CrossValidationSettings coarse;
  coarse.weight_steps = 3;
  const std::vector<Method> four = {parse_method("iclap+icp+bow+iclapn")};
  CHECK(error_of([&] { CrossValidation<>(five, all_classifiers, codebook(4), four, coarse); })
            .find("weight_steps | is 3, fewer than the 4 terms of method 'iclap+icp+bow+iclapn'") == 0);
  coarse.zero_weights = true;
  CHECK_NOTHROW(CrossValidation<>(five, all_classifiers, codebook(4), four, coarse));
  // A grid too large to search is refused before it is built (4 terms of
  // 1000 steps: 1.7e8 vectors, which weight_grid would have allocated).
  CrossValidationSettings fine;
  fine.weight_steps = 1000;
  CHECK(error_of([&] { CrossValidation<>(five, all_classifiers, codebook(4), four, fine); })
            .find("weight_steps | is 1000: the grid of the 4 terms of method 'iclap+icp+bow+iclapn'") == 0);
  // More draws than the random streams tell apart are refused.
  CrossValidationSettings many;
  many.repeats = CrossValidationSettings::kMaxRepeats + 1;
  CHECK(error_of([&] { many.validate(); }).find("repeats | must be >= 1 and <= 1048576") == 0);
  many.repeats = CrossValidationSettings::kMaxRepeats;
  CHECK_NOTHROW(many.validate());
  many.weight_repeats = CrossValidationSettings::kMaxRepeats + 1;
  CHECK(error_of([&] { many.validate(); }).find("weight_repeats | must be >= 1 and <= 1048576") == 0);

  // A hand-built table whose per-touch vectors disagree, or whose object
  // index is out of range, is refused (both read out of bounds).
  TouchTable wrong = five;
  wrong.object.back() = static_cast<Index>(wrong.objects.size());
  CHECK(error_of([&] { CrossValidation<>(wrong, only_bow, codebook(4), {parse_method("bow")}); })
            .find("table.object | touch " + std::to_string(wrong.size() - 1) + " has object index 3, outside [0, 3)") ==
        0);
  wrong = five;
  wrong.object.pop_back();
  CHECK_THROWS_AS(CrossValidation<>(wrong, only_bow, codebook(4), {parse_method("bow")}), DimensionMismatch);
  wrong = five;
  wrong.frame.push_back(0);
  CHECK_THROWS_AS(wrong.select({0, 1}), DimensionMismatch);
  // Fewer feature columns than touches (the codebook read past them).
  wrong = five;
  wrong.touches.features.conservativeResize(Eigen::NoChange, wrong.size() - 10);
  CHECK(error_of([&] { CrossValidation<>(wrong, only_bow, codebook(4), {parse_method("bow")}); })
            .find("table.touches.features (touches) | has dimension " + std::to_string(wrong.size() - 10)) == 0);
  wrong = five;
  wrong.touches.positions(2, 7) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(CrossValidation<>(wrong, only_bow, codebook(4), {parse_method("bow")}), NonFiniteValue);
}

TEST_CASE("cross validation refuses a table of one object; the classifiers still measure one reference") {
  const TouchTable t = synthetic_table(3);
  std::vector<Index> rows;
  for (Index i = 0; i < t.size(); ++i)
    if (t.object[static_cast<std::size_t>(i)] == 0) rows.push_back(i);
  TouchTable one = t.select(rows);
  one.objects.resize(1);
  // Among one object every test is "recognised": 100% for every method,
  // whatever was touched (before, it ran and reported exactly that).
  CHECK(error_of([&] { CrossValidation<>(one, all_classifiers, codebook(4), {parse_method("bow")}); }) ==
        "table | 1 object ('" + t.objects[0] + "'); recognition needs at least 2 objects to choose among");
  // Refused before anything else about the table's explorations.
  TouchTable one_exploration = one;
  for (auto& e : one_exploration.exploration) e = 0;
  CHECK(error_of([&] { CrossValidation<>(one_exploration, all_classifiers, codebook(4), {parse_method("bow")}); })
            .find("table | 1 object") == 0);
  CHECK(CrossValidation<>(t, all_classifiers, codebook(4), {parse_method("bow")}).folds() == 4);

  // A recogniser (and its classifiers) fitted on one object is legitimate:
  // distances to a single reference.
  KMeansQuantizer<float> q = codebook(4);
  q.fit(one.touches.features);
  TouchSet all = one.touches;
  all.words = assign_words(q, one.touches.features);
  Recognizer rec(all_classifiers());
  rec.fit({all}, q.size());
  const DistanceTable table = rec.distances(all);
  CHECK(table.objects() == 1);
  CHECK(decide(parse_method("iclap+icp+bow").fusion.evaluate(table)) == 0);
}

TEST_CASE("cross validation: every fold, inner fold and object draws from a random stream of its own") {
  using CV = CrossValidation<>;
  // The streams the results files of this repository were drawn with.
  CHECK(CV::draw_stream(0, -1, 0) == 0);
  CHECK(CV::draw_stream(4, -1, 19) == ((std::uint64_t{4} << 40) ^ 19));
  CHECK(CV::draw_stream(3, 2, 7) == ((std::uint64_t{3} << 40) ^ (std::uint64_t{3} << 32) ^ 7));
  CHECK(CV::draw_stream(300, 254, 5) == ((std::uint64_t{300} << 40) ^ (std::uint64_t{255} << 32) ^ 5));
  // Distinct for all of them, with 256 and more explorations per object
  // too (inner + 1 >= 256 once packed into the fold's bits) and at the
  // extremes: the fold limit and objects up to 2^31 - 1.
  std::vector<std::uint64_t> streams;
  const std::vector<int> folds = {0, 1, 2, 255, 256, 257, 299, CV::kMaxFolds - 1};
  const std::vector<Index> objects = {0, 1, 2, 255, 256, (Index{1} << 31) - 1};
  for (const int f : folds)
    for (const int inner : {-1, 0, 1, 254, 255, 256, 298, 299, CV::kMaxFolds - 1})
      for (const Index o : objects) streams.push_back(CV::draw_stream(f, inner, o));
  for (int f = 0; f < 300; ++f)
    for (int inner = -1; inner < 300; ++inner)
      for (Index o = 0; o < 3; ++o) streams.push_back(CV::draw_stream(f, inner, o));
  std::sort(streams.begin(), streams.end());
  const std::size_t all = streams.size();
  streams.erase(std::unique(streams.begin(), streams.end()), streams.end());
  // Only the tuples listed twice (both loops) may repeat.
  std::size_t twice = 0;
  for (const int f : folds)
    for (const int inner : {-1, 0, 1, 254, 255, 256, 298, 299, CV::kMaxFolds - 1})
      for (const Index o : objects) twice += f < 300 && inner < 300 && o < 3;
  CHECK(streams.size() == all - twice);
  // An old collision: fold 0's inner fold 255 took fold 1's outer stream.
  CHECK(CV::draw_stream(0, 255, 0) != CV::draw_stream(1, -1, 0));

  // More folds than that are refused: each object's first touch as many
  // one-touch explorations as there are streams, then one more.
  const TouchTable t = synthetic_table(2);
  auto only_bow = [] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<BowClassifier>());
    return cs;
  };
  for (const int explorations : {CV::kMaxFolds, CV::kMaxFolds + 1}) {
    CAPTURE(explorations);
    std::vector<Index> rows;
    for (Index o = 0; o < static_cast<Index>(t.objects.size()); ++o) {
      const auto first = std::find(t.object.begin(), t.object.end(), o) - t.object.begin();
      rows.insert(rows.end(), static_cast<std::size_t>(explorations), static_cast<Index>(first));
    }
    TouchTable many = t.select(rows);
    for (std::size_t i = 0; i < many.exploration.size(); ++i)
      many.exploration[i] = static_cast<std::int64_t>(i % static_cast<std::size_t>(explorations));
    const std::string error = error_of([&] { CV(many, only_bow, codebook(4), {parse_method("bow")}); });
    if (explorations == CV::kMaxFolds)
      CHECK(error == "(no error)");
    else
      CHECK(error == "table | every object has at least 65536 explorations, which makes more folds than the 65535 "
                     "whose test draws have random streams of their own");
  }
}

TEST_CASE("largest_held_out: the most touches of an exploration that a fold holds out") {
  const TouchTable t = synthetic_table(3);  // 25 touches in every exploration
  CHECK(CrossValidation<>(t, test::paper_classifiers, codebook(4), {parse_method("bow")}).largest_held_out() == 25);
  // Five more touches in one exploration of the ring; a fifth exploration of
  // the bar, of 40 touches, is never held out (the others have 4: 4 folds).
  std::vector<Index> rows(static_cast<std::size_t>(t.size()));
  for (Index i = 0; i < t.size(); ++i) rows[static_cast<std::size_t>(i)] = i;
  const auto ring = std::find(t.object.begin(), t.object.end(), 1) - t.object.begin();
  rows.insert(rows.end(), 5, static_cast<Index>(ring));
  rows.insert(rows.end(), 40, 0);
  TouchTable more = t.select(rows);
  for (std::size_t i = more.exploration.size() - 40; i < more.exploration.size(); ++i) more.exploration[i] = 14;
  CrossValidation<> cv(more, test::paper_classifiers, codebook(4), {parse_method("bow")});
  CHECK(cv.folds() == 4);
  CHECK(cv.largest_held_out() == 30);
}

TEST_CASE("weights chosen on inner folds need 3 explorations of every object, fixed weights 2") {
  const TouchTable full = synthetic_table(6);  // explorations 10..13
  std::vector<Index> rows;
  for (Index i = 0; i < full.size(); ++i)
    if (full.exploration[static_cast<std::size_t>(i)] <= 11) rows.push_back(i);
  const TouchTable two = full.select(rows);
  CrossValidationSettings s;
  s.touches = {1, 3};
  s.repeats = 2;
  CHECK_THROWS_WITH_AS(CrossValidation<>(two, test::paper_classifiers, codebook(4),
                                         {parse_method("bow"), parse_method("icp+bow")}, s),
                       "table: object 'bar' has 2 explorations with touches; method 'icp+bow' is chosen on inner "
                       "folds of each fold's training explorations (weights or trimming), which needs at least 3 "
                       "explorations of every object (give fixed weights and trimming, which need only 2)",
                       InvalidArgument);
  // Fixed weights and single classifiers need no inner folds.
  CrossValidation<> fixed(two, test::paper_classifiers, codebook(4),
                          {parse_method("bow"), parse_method("0.5*icp+0.5*bow")}, s);
  const CrossValidationResult r = fixed.run();
  CHECK(r.folds == 2);
  CHECK(r.methods.size() == 2);
  CHECK(r.methods.at(1).total.at(1) > 0);
  // With a third exploration, the fitted weights run.
  rows.clear();
  for (Index i = 0; i < full.size(); ++i)
    if (full.exploration[static_cast<std::size_t>(i)] <= 12) rows.push_back(i);
  // The table is kept by reference, so a temporary one does not compile.
  static_assert(!std::is_constructible_v<CrossValidation<>, TouchTable, ClassifierFactory, KMeansQuantizer<float>,
                                         std::vector<Method>, CrossValidationSettings>);
  static_assert(std::is_constructible_v<CrossValidation<>, const TouchTable&, ClassifierFactory,
                                        KMeansQuantizer<float>, std::vector<Method>, CrossValidationSettings>);
  const TouchTable three_explorations = full.select(rows);
  CrossValidation<> three(three_explorations, test::paper_classifiers, codebook(4), {parse_method("icp+bow")}, s);
  CHECK(three.run().folds == 3);
}

namespace {
/// A k-means codebook that records the features of every fit (copies share
/// the record, as CrossValidation fits copies).
struct RecordingQuantizer {
  KMeansQuantizer<float> inner = codebook(4);
  std::shared_ptr<std::vector<Eigen::MatrixXf>> fits = std::make_shared<std::vector<Eigen::MatrixXf>>();
  void fit(const Eigen::MatrixXf& features) {
    fits->push_back(features);
    inner.fit(features);
  }
  template <typename Feature>
  Index assign(const Feature& f) const {
    return inner.assign(f);
  }
  Index size() const { return inner.size(); }
};

/// A RecordingQuantizer with the optional check(): records, in one log with
/// the fits, every set of features it checks.
struct CheckingQuantizer : RecordingQuantizer {
  std::shared_ptr<std::vector<Eigen::MatrixXf>> checks = std::make_shared<std::vector<Eigen::MatrixXf>>();
  std::shared_ptr<std::string> log = std::make_shared<std::string>();  // 'c' per check, 'f' per fit
  void check(const Eigen::MatrixXf& features) const {
    checks->push_back(features);
    *log += 'c';
    inner.check(features);
  }
  void fit(const Eigen::MatrixXf& features) {
    *log += 'f';
    RecordingQuantizer::fit(features);
  }
};
static_assert(is_checkable_quantizer_v<CheckingQuantizer, Eigen::MatrixXf>);
static_assert(!is_checkable_quantizer_v<RecordingQuantizer, Eigen::MatrixXf>);

/// The features of the touches of `t` whose exploration is not in `out`, in
/// table order.
Eigen::MatrixXf features_without(const TouchTable& t, const std::vector<std::int64_t>& out) {
  std::vector<Index> keep;
  for (Index i = 0; i < t.size(); ++i)
    if (std::find(out.begin(), out.end(), t.exploration[static_cast<std::size_t>(i)]) == out.end()) keep.push_back(i);
  return t.touches.features(Eigen::all, keep);
}

bool same(const Eigen::MatrixXf& a, const Eigen::MatrixXf& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}
}  // namespace

TEST_CASE("inner_codebooks: every inner fold fits its codebook without its held-out exploration") {
  const TouchTable t = synthetic_table(4);  // explorations 10..13
  CrossValidationSettings s;
  s.touches = {1, 3};
  s.repeats = 3;
  s.weight_repeats = 2;
  s.seed = 5;
  s.threads = 2;
  const std::vector<Method> methods = {parse_method("bow"), parse_method("icp+bow")};
  RecordingQuantizer plain_q, nested_q;
  CrossValidation<RecordingQuantizer> plain(t, test::paper_classifiers, plain_q, methods, s);
  const CrossValidationResult a = plain.run();
  s.inner_codebooks = true;
  CrossValidation<RecordingQuantizer> nested(t, test::paper_classifiers, nested_q, methods, s);
  const CrossValidationResult b = nested.run();

  // Without: one codebook per fold, fitted on its three training explorations.
  REQUIRE(plain_q.fits->size() == 4);
  for (std::int64_t f = 0; f < 4; ++f) CHECK(same((*plain_q.fits)[static_cast<std::size_t>(f)], features_without(t, {10 + f})));
  // With: the fold's codebook, then one per inner fold, without the inner
  // held-out exploration either.
  REQUIRE(nested_q.fits->size() == 4 * (1 + 3));
  std::size_t k = 0;
  for (std::int64_t f = 0; f < 4; ++f) {
    CHECK(same((*nested_q.fits)[k++], features_without(t, {10 + f})));
    for (std::int64_t g = 0; g < 4; ++g)
      if (g != f) CHECK(same((*nested_q.fits)[k++], features_without(t, {10 + f, 10 + g})));
  }
  // codebook_trainings() names the same touches without a run (folds first,
  // then every fold's inner folds), for checks before it; with nothing
  // chosen on inner folds there are no inner codebooks.
  const auto plain_sets = plain.codebook_trainings();
  REQUIRE(plain_sets.size() == 4);
  for (std::size_t f = 0; f < 4; ++f) CHECK(same(t.touches.features(Eigen::all, plain_sets[f]), (*plain_q.fits)[f]));
  const auto nested_sets = nested.codebook_trainings();
  REQUIRE(nested_sets.size() == 4 * (1 + 3));
  for (std::size_t f = 0, n = 0; f < 4; ++f) {
    CHECK(same(t.touches.features(Eigen::all, nested_sets[f]), (*nested_q.fits)[n++]));
    for (std::size_t g = 0; g < 3; ++g)
      CHECK(same(t.touches.features(Eigen::all, nested_sets[4 + 3 * f + g]), (*nested_q.fits)[n++]));
  }
  CHECK(CrossValidation<RecordingQuantizer>(t, test::paper_classifiers, RecordingQuantizer{}, {parse_method("bow")}, s)
            .codebook_trainings()
            .size() == 4);

  // A quantizer with check() has it called on the same sets, before any
  // fit; run() calls it first too. One without check() is not checked.
  CheckingQuantizer checking_q;
  CrossValidation<CheckingQuantizer> checking(t, test::paper_classifiers, checking_q, methods, s);
  checking.check_codebooks();
  REQUIRE(checking_q.checks->size() == nested_sets.size());
  for (std::size_t i = 0; i < nested_sets.size(); ++i)
    CHECK(same(t.touches.features(Eigen::all, nested_sets[i]), (*checking_q.checks)[i]));
  CHECK(checking_q.fits->empty());
  checking_q.log->clear();
  (void)checking.run();
  CHECK(*checking_q.log == std::string(nested_sets.size(), 'c') + std::string(nested_sets.size(), 'f'));
  plain.check_codebooks();  // RecordingQuantizer has no check(): nothing to call
  CHECK(plain_q.fits->size() == 4);
  // A codebook too large for the inner folds' training touches alone, not
  // the folds': refused by run() before the first fit.
  std::size_t fewest = nested_sets.front().size();
  for (const auto& set : nested_sets) fewest = std::min(fewest, set.size());
  REQUIRE(fewest < nested_sets.front().size());
  CheckingQuantizer big_q;
  big_q.inner.settings.k = static_cast<Index>(fewest) + 1;
  CrossValidation<CheckingQuantizer> big(t, test::paper_classifiers, big_q, methods, s);
  CHECK(test::what_of([&] { (void)big.run(); }) == "settings.k: k = " + std::to_string(fewest + 1) +
                                                       " exceeds the number of features (" + std::to_string(fewest) +
                                                       ")");
  CHECK(big_q.fits->empty());
  CHECK(*big_q.log == std::string(4 + 1, 'c'));  // the 4 folds' sets, then the first inner fold's

  // The outer test uses the fold's codebook either way: a method without
  // fitted weights recognises exactly as before.
  CHECK(a.vocabulary == b.vocabulary);
  CHECK(a.methods[0].correct == b.methods[0].correct);
  CHECK(a.methods[0].confusion == b.methods[0].confusion);
  // The fitted method still has weights summing to 1 in every fold.
  REQUIRE(b.methods[1].fold_weights.size() == 4);
  for (const auto& w : b.methods[1].fold_weights) CHECK(w[0] + w[1] == doctest::Approx(1.0));
}

namespace {
/// What one fitted classifier saw: the table rows of its references and of
/// every test set it was asked about.
struct FitRecord {
  std::set<Index> references;
  std::vector<std::vector<Index>> tests;
};
struct FitLog {
  std::mutex mutex;
  std::vector<FitRecord> fits;  // in fit order
};

/// A classifier that reads each touch's table row, object and exploration
/// rank off its position (x, y, z), as `tagged_table` writes them, and gives
/// distance 0 to object (truth + shift) mod N and 1 to the others: shift 0
/// is always right, shift 1 always names the next object. With a log, it
/// records every fit and test set.
struct Oracle final : Classifier {
  std::string label;
  Index shift = 0;
  std::shared_ptr<FitLog> log;
  Index n = 0;
  std::size_t record = 0;
  Oracle(std::string name, Index s, std::shared_ptr<FitLog> l = nullptr)
      : label(std::move(name)), shift(s), log(std::move(l)) {}
  std::string name() const override { return label; }
  void fit(const std::vector<TouchSet>& objects, Index) override {
    n = static_cast<Index>(objects.size());
    if (!log) return;
    const std::lock_guard<std::mutex> lock(log->mutex);
    record = log->fits.size();
    log->fits.emplace_back();
    for (const auto& o : objects)
      for (Index i = 0; i < o.size(); ++i) log->fits.back().references.insert(row_of(o, i));
  }
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    const auto truth = static_cast<Index>(std::lround(test.positions(1, 0)));
    out.setOnes();
    out((truth + shift) % n) = 0;
    if (!log) return;
    std::vector<Index> rows;
    for (Index i = 0; i < test.size(); ++i) rows.push_back(row_of(test, i));
    const std::lock_guard<std::mutex> lock(log->mutex);
    log->fits[record].tests.push_back(rows);
  }
  Index objects() const override { return n; }
  static Index row_of(const TouchSet& s, Index i) { return static_cast<Index>(std::lround(s.positions(0, i))); }
};

/// synthetic_table(seed) with each touch's position replaced by (table row,
/// object, exploration rank), for Oracle.
TouchTable tagged_table(std::uint64_t seed) {
  TouchTable t = synthetic_table(seed);
  for (Index i = 0; i < t.size(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    t.touches.positions.col(i) = Eigen::Vector3d(static_cast<double>(i), static_cast<double>(t.object[k]),
                                                 static_cast<double>(t.exploration[k] - 10));
  }
  return t;
}
}  // namespace

TEST_CASE("cross validation: each fold and inner fold fits on its training explorations and tests the held-out one") {
  const TouchTable t = tagged_table(4);  // 3 objects x explorations 10..13 x 25 touches, rows in that order
  const auto log = std::make_shared<FitLog>();
  auto factory = [log] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<Oracle>("right", 0, log));
    cs.push_back(std::make_unique<Oracle>("wrong", 1));
    return cs;
  };
  CrossValidationSettings s;
  s.touches = {1, 24, 30};  // 30: more than an exploration has
  s.repeats = 3;
  s.weight_repeats = 2;
  s.seed = 11;
  s.threads = 1;
  const auto r = CrossValidation<>(t, factory, codebook(4), {parse_method("right+wrong")}, s).run();
  const auto rank = [&](Index row) { return static_cast<int>(t.exploration[static_cast<std::size_t>(row)] - 10); };
  const auto object = [&](Index row) { return t.object[static_cast<std::size_t>(row)]; };
  const auto rows_without = [&](int a, int b) {
    std::set<Index> out;
    for (Index i = 0; i < t.size(); ++i)
      if (rank(i) != a && rank(i) != b) out.insert(i);
    return out;
  };

  // Per outer fold f: an inner fold for each other exploration g, then the
  // outer test. Every fit's references are its training explorations, and
  // it is tested on its held-out one only, never on the outer test.
  REQUIRE(log->fits.size() == 4 * 4);
  for (int f = 0; f < 4; ++f) {
    std::size_t at = static_cast<std::size_t>(4 * f);
    for (int g = 0; g < 4; ++g) {
      if (g == f) continue;
      CAPTURE(f);
      CAPTURE(g);
      const FitRecord& inner = log->fits[at++];
      CHECK(inner.references == rows_without(f, g));
      CHECK(inner.tests.size() == 3 * 3 * 2);  // objects x touch counts x weight_repeats
      for (const auto& test : inner.tests)
        for (Index row : test) CHECK(rank(row) == g);
    }
    CAPTURE(f);
    const FitRecord& outer = log->fits[at];
    CHECK(outer.references == rows_without(f, f));
    REQUIRE(outer.tests.size() == 3 * 3 * 3);  // objects x touch counts x repeats
    // Draws of one object's held-out touches, without repeats, capped at 25.
    std::map<std::pair<Index, std::size_t>, std::vector<std::vector<Index>>> draws;  // (object, size) -> draws
    for (const auto& test : outer.tests) {
      std::set<Index> distinct(test.begin(), test.end());
      CHECK(distinct.size() == test.size());
      for (Index row : test) {
        CHECK(rank(row) == f);
        CHECK(object(row) == object(test.front()));
      }
      // As offsets into the exploration's 25 rows, to compare objects.
      std::vector<Index> offsets;
      for (Index row : test) offsets.push_back(row % 25);
      draws[{object(test.front()), test.size()}].push_back(offsets);
    }
    for (Index o = 0; o < 3; ++o) {
      CAPTURE(o);
      for (std::size_t size : {std::size_t{1}, std::size_t{24}, std::size_t{25}}) CHECK(draws[{o, size}].size() == 3);
      // Each repeat, touch count, object and fold has a random stream of its
      // own: the three 24-touch draws differ, and differ from another
      // object's; and across all of them any touch can be the one left out.
      const auto& d24 = draws[{o, 24}];
      CHECK((d24[0] != d24[1] || d24[1] != d24[2]));
      CHECK(d24 != draws[{(o + 1) % 3, 24}]);
    }
  }
  std::set<Index> left_out;
  for (std::size_t k = 3; k < log->fits.size(); k += 4)
    for (const auto& test : log->fits[k].tests)
      if (test.size() == 24)
        for (Index offset = 0; offset < 25; ++offset)
          if (std::none_of(test.begin(), test.end(), [&](Index row) { return row % 25 == offset; }))
            left_out.insert(offset);
  CHECK(left_out.size() > 1);
  // Only the outer test's 30-touch draws count as capped.
  CHECK(r.capped_draws == 4 * 3 * 3);
}

TEST_CASE("cross validation: fitted weights win on rate, then on margin; the sweep counts every grid vector") {
  // right + wrong: w right + (1 - w) wrong recognises every test for w >= 0.6,
  // the objects whose successor has a larger index at w = 0.5 (the tie goes to
  // the smaller index), none below. The margin grows with w, so 0.9 wins.
  const TouchTable t = tagged_table(4);
  auto factory = [] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<Oracle>("right", 0));
    cs.push_back(std::make_unique<Oracle>("wrong", 1));
    return cs;
  };
  CrossValidationSettings s;
  s.touches = {1, 3};
  s.repeats = 2;
  s.weight_repeats = 1;
  const auto r = CrossValidation<>(t, factory, codebook(4), {parse_method("right+wrong")}, s).run();
  const MethodResult& m = r.methods.at(0);
  CHECK(m.fold_weights == std::vector<std::vector<double>>(4, weight_grid(2).back()));
  CHECK(m.correct == std::vector<Index>{24, 24});
  REQUIRE(r.sweeps.size() == 1);
  const WeightSweep& sw = r.sweeps[0];
  REQUIRE(sw.grid == weight_grid(2));
  CHECK(sw.total == std::vector<Index>{24, 24});
  for (std::size_t g = 0; g < sw.grid.size(); ++g) {
    CAPTURE(g);
    const Index expected = g < 4 ? 0 : g == 4 ? 16 : 24;  // w = 0.1 .. 0.4, 0.5, 0.6 .. 0.9
    CHECK(sw.correct[g] == std::vector<Index>{expected, expected});
  }
}

// --- Audit (session 51, helper-47): reproducers of defects, fixed since.

TEST_CASE("audit: a method that fits weights must be a weighted sum, refused at construction otherwise") {
  // Expected (CrossValidation's constructor doc, Method::validate): a method
  // whose weights are to be fitted but whose fusion is no weighted sum (a
  // classifier alone, a product) is refused at construction, InvalidArgument
  // naming "methods" and the method. Happened: Method::validate checks only
  // the alternatives, check_weight_steps counts 0 (or the factors') terms,
  // so construction succeeds; run() then fails with "terms: must be at least
  // 1, got 0" (no method named), or, for the product, after fitting the
  // inner folds, with "weights: only a weighted sum has weights: icp*bow".
  const TouchTable t = synthetic_table(5);
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow");
  for (const Method& m : {Method{"icp", icp, true, {}}, Method{"icp*bow", icp * bow, true, {}}}) {
    CAPTURE(m.name);
    CHECK(error_of([&] { m.validate(); }).find("methods | ") == 0);
    CHECK(error_of([&] { CrossValidation<>(t, test::paper_classifiers, codebook(4), {m}); })
              .find("methods | method '" + m.name + "'") == 0);
  }
}

TEST_CASE("audit: a number of touches listed twice is refused, as iclap evaluate refuses it") {
  // Expected: CrossValidationSettings::validate refuses touches = {2, 2}
  // (InvalidArgument naming "touches"), as `iclap evaluate --touches 2,2`
  // does ("--touches: 2 is listed twice"): the second entry draws the very
  // same test sets (the draw's stream depends on the count, not on its
  // position), so it is one result under two columns, and a caller that
  // sums over the columns counts those tests twice. Happened: accepted; run()
  // reports two identical columns.
  CrossValidationSettings s;
  s.touches = {2, 3, 2};
  CHECK(error_of([&] { s.validate(); }).find("touches | ") == 0);
  // The engine refuses it at construction too (it reported two identical
  // columns for 2 touches: same totals, same correct counts).
  s.touches = {2, 2};
  const TouchTable t = synthetic_table(5);
  auto only_bow = [] {
    std::vector<std::unique_ptr<Classifier>> cs;
    cs.push_back(std::make_unique<BowClassifier>());
    return cs;
  };
  CHECK(error_of([&] { CrossValidation<>(t, only_bow, codebook(4), {parse_method("bow")}, s); }).find("touches | ") ==
        0);
}

TEST_CASE("audit: a method listed twice, under one name or two spellings, is refused") {
  // Expected: CrossValidation refuses a method list that runs one method
  // twice (InvalidArgument naming "methods"), as `iclap evaluate --methods
  // icp+bow,bow+icp` does with method_key, whose doc gives this very use;
  // and two methods of one name, whose results could not be told apart.
  // Happened: both lists are accepted; the run computes the method twice
  // and reports two results of one name.
  const TouchTable t = synthetic_table(5);
  CHECK(method_key(parse_method("icp+bow")) == method_key(parse_method("bow+icp")));
  CHECK(error_of([&] {
          CrossValidation<>(t, test::paper_classifiers, codebook(4), {parse_method("icp+bow"), parse_method("bow+icp")});
        }).find("methods | ") == 0);
  Method other = parse_method("icp");
  other.name = "bow";
  CHECK(error_of([&] {
          CrossValidation<>(t, test::paper_classifiers, codebook(4), {parse_method("bow"), other});
        }).find("methods | ") == 0);
}
