// SPDX-License-Identifier: MIT
// Fusion algebra, method names and weight grids, normalisation, decisions.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include "iclap/recognition/recognition.hpp"
#include "fusion_test_util.hpp"
#include "../support/child_outcome.hpp"

using namespace iclap;
using iclap::test::error_of;
using iclap::test::vec;

namespace {
DistanceTable table_of(std::initializer_list<std::pair<const char*, Eigen::VectorXd>> entries) {
  DistanceTable t;
  for (const auto& e : entries) t.set(e.first, e.second);
  return t;
}
}  // namespace

TEST_CASE("the paper's three-way fusion in one line") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow"), iclap = Fusion::classifier("iclap");
  const Fusion all = 0.2 * icp + 0.2 * bow + 0.6 * iclap;
  const auto t = table_of({{"icp", vec({0.1, 0.5, 0.8})}, {"bow", vec({0.4, 0.2, 0.9})}, {"iclap", vec({0.3, 0.6, 0.1})}});
  const Eigen::VectorXd e = all.evaluate(t);
  CHECK(e(0) == doctest::Approx(0.2 * 0.1 + 0.2 * 0.4 + 0.6 * 0.3));
  CHECK(e(1) == doctest::Approx(0.2 * 0.5 + 0.2 * 0.2 + 0.6 * 0.6));
  CHECK(e(2) == doctest::Approx(0.2 * 0.8 + 0.2 * 0.9 + 0.6 * 0.1));
  CHECK(decide(e) == 0);
  CHECK(all.to_string() == "0.2*icp+0.2*bow+0.6*iclap");
  CHECK(all.classifiers() == std::vector<std::string>{"icp", "bow", "iclap"});

  const Fusion prod = icp * bow * iclap;
  CHECK(prod.kind() == Fusion::Kind::Product);
  CHECK(prod.children().size() == 3);  // flattened
  CHECK(prod.evaluate(t)(1) == doctest::Approx(0.5 * 0.2 * 0.6));
  CHECK(prod.to_string() == "icp*bow*iclap");
}

TEST_CASE("fusions nest") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow"), iclap = Fusion::classifier("iclap");
  const Fusion inner = 0.5 * icp + 0.5 * bow;
  const Fusion nested = 0.4 * (icp * bow) + 0.6 * (inner * iclap);
  const auto t = table_of({{"icp", vec({0.2, 0.4})}, {"bow", vec({0.6, 0.8})}, {"iclap", vec({1.0, 0.5})}});
  const Eigen::VectorXd e = nested.evaluate(t);
  CHECK(e(0) == doctest::Approx(0.4 * 0.2 * 0.6 + 0.6 * (0.5 * 0.2 + 0.5 * 0.6) * 1.0));
  CHECK(e(1) == doctest::Approx(0.4 * 0.4 * 0.8 + 0.6 * (0.5 * 0.4 + 0.5 * 0.8) * 0.5));
  CHECK(nested.to_string() == "0.4*icp*bow+0.6*(0.5*icp+0.5*bow)*iclap");
  CHECK(parse_method("0.4*icp*bow+0.6*(0.5*icp+0.5*bow)*iclap").fusion.evaluate(t).isApprox(e));
}

TEST_CASE("bad compositions fail at construction with a clear message") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow");
  CHECK(error_of([&] { Fusion f = 0.2 * icp + 0.7 * bow; }) ==
        "weights | weights: the weights sum to 0.9, not 1, in 0.2*icp+0.7*bow");
  CHECK(error_of([&] { Fusion f = -0.5 * icp + 1.5 * bow; }).find("negative weight -0.5 for icp") != std::string::npos);
  CHECK(error_of([&] { Fusion::weighted_sum({}); }).find("at least one term") != std::string::npos);
  CHECK(error_of([&] { Fusion::classifier("a b"); }).find("classifier") == 0);
  CHECK(error_of([&] { Fusion f = std::numeric_limits<double>::quiet_NaN() * icp + 1.0 * bow; }).find("not finite") !=
        std::string::npos);
  // A classifier the recogniser does not have.
  std::vector<std::unique_ptr<Classifier>> cs;
  cs.push_back(std::make_unique<BowClassifier>());
  const Recognizer rec(std::move(cs));
  CHECK(error_of([&] { rec.check({parse_method("icp+bow")}); }) ==
        "methods | methods: method 'icp+bow' needs classifier 'icp', which is not among the classifiers (bow)");
  // Products of signed (z-scored) distances.
  std::vector<std::unique_ptr<Classifier>> cs2;
  cs2.push_back(std::make_unique<BowClassifier>());
  const Recognizer zrec(std::move(cs2), Normalization::ZScore);
  CHECK(error_of([&] { zrec.check({Method{"bow*bow", bow * bow, false, {}}}); }).find("z-score") != std::string::npos);
  CHECK_NOTHROW(zrec.check({parse_method("bow")}));
  // Evaluating without a classifier's distances.
  const auto t = table_of({{"icp", vec({0.1, 0.2})}});
  CHECK(error_of([&] { (icp * bow).evaluate(t); }).find("'bow' has no distances") != std::string::npos);
  // Mismatched lengths in one table.
  DistanceTable bad;
  bad.set("icp", vec({1, 2}));
  CHECK_THROWS_AS(bad.set("bow", vec({1, 2, 3})), DimensionMismatch);
}

TEST_CASE("product with a zero distance, and deterministic ties") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow");
  const auto t = table_of({{"icp", vec({0.7, 0.0, 0.5})}, {"bow", vec({0.1, 0.9, 0.05})}});
  // The zero wins the product whatever the other factor says.
  CHECK(decide((icp * bow).evaluate(t)) == 1);
  // Two zeros: the smaller index wins.
  const auto z = table_of({{"icp", vec({0.7, 0.0, 0.0})}, {"bow", vec({0.1, 0.9, 0.05})}});
  CHECK(decide((icp * bow).evaluate(z)) == 1);
  CHECK(decide(vec({0.3, 0.1, 0.1, 0.2})) == 1);
  CHECK(decide(vec({0.5, 0.5})) == 0);
  CHECK(decide(Eigen::VectorXd()) == -1);
  // Negative inputs to a product are refused.
  const auto neg = table_of({{"icp", vec({-0.7, 0.0})}, {"bow", vec({0.1, 0.9})}});
  CHECK(error_of([&] { (icp * bow).evaluate(neg); }).find("non-negative") != std::string::npos);
  // So is a negative distance that is not the first entry.
  const auto neg_last = table_of({{"icp", vec({0.7, -0.1})}, {"bow", vec({0.1, 0.9})}});
  CHECK(error_of([&] { (icp * bow).evaluate(neg_last); }).find("non-negative") != std::string::npos);
}

TEST_CASE("a NaN or infinity is refused, never passed on or decided by its position") {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  DistanceTable t;
  // A NaN loses every comparison: decided as is, {nan, 0.35} went to object 0.
  try {
    t.set("icp", vec({0.2, nan}));
    FAIL("a NaN distance was taken");
  } catch (const NonFiniteValue& e) {
    CHECK(std::string(e.argument()) == "distances of 'icp'");
    CHECK(std::string(e.what()).find("row 1") != std::string::npos);
  }
  CHECK_THROWS_AS(t.set("bow", vec({inf, 0.1})), NonFiniteValue);
  CHECK_FALSE(t.has("icp"));
  CHECK_THROWS_AS(decide(vec({nan, 0.1})), NonFiniteValue);
  CHECK_THROWS_AS(decide(vec({0.1, -inf})), NonFiniteValue);
  CHECK_THROWS_AS(decision_confidence(vec({nan, 0.5})), NonFiniteValue);
  CHECK_THROWS_AS(decision_confidence(vec({0.5, nan})), NonFiniteValue);
  CHECK_THROWS_AS(decision_confidence(vec({inf, inf})), NonFiniteValue);
  // A product of finite raw distances that overflows names the product.
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow");
  const auto huge = table_of({{"icp", vec({1e200, 1.0})}, {"bow", vec({1e200, 2.0})}});
  try {
    (icp * bow).evaluate(huge);
    FAIL("an overflowing product was passed on");
  } catch (const NonFiniteValue& e) {
    CHECK(std::string(e.argument()) == "product icp*bow");
  }
}

TEST_CASE("DistanceTable: setting a classifier again replaces its distances, checked like the first time") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow");
  DistanceTable t;
  t.set("icp", vec({0.9, 0.1, 0.5}));
  t.set("bow", vec({0.2, 0.4, 0.6}));
  CHECK(decide(icp.evaluate(t)) == 1);
  t.set("icp", vec({0.1, 0.8, 0.3}));
  // The new distances are the ones used, by get and by every fusion; the
  // other classifier's are untouched and the table still has 3 objects.
  CHECK(t.get("icp") == vec({0.1, 0.8, 0.3}));
  CHECK(t.get("bow") == vec({0.2, 0.4, 0.6}));
  CHECK(t.objects() == 3);
  CHECK(t.has("icp"));
  CHECK(decide(icp.evaluate(t)) == 0);
  CHECK(Fusion(0.5 * icp + 0.5 * bow).evaluate(t).isApprox(vec({0.15, 0.6, 0.45})));
  CHECK((icp * bow).evaluate(t).isApprox(vec({0.02, 0.32, 0.18})));
  // The second classifier can be replaced too, again and again.
  t.set("bow", vec({0.7, 0.0, 0.1}));
  t.set("bow", vec({0.6, 0.05, 0.2}));
  CHECK(t.get("bow") == vec({0.6, 0.05, 0.2}));
  CHECK(t.get("icp") == vec({0.1, 0.8, 0.3}));
  CHECK(decide(bow.evaluate(t)) == 1);
  // A replacement of the wrong length or with a NaN is refused naming the
  // classifier, and the distances stay as they were.
  try {
    t.set("icp", vec({0.1, 0.2}));
    FAIL("a replacement of the wrong length was taken");
  } catch (const DimensionMismatch& e) {
    CHECK(e.argument() == "distances of 'icp'");
    CHECK(e.expected() == 3);
    CHECK(e.actual() == 2);
  }
  CHECK_THROWS_AS(t.set("icp", vec({0.1, std::numeric_limits<double>::quiet_NaN(), 0.3})), NonFiniteValue);
  CHECK(t.get("icp") == vec({0.1, 0.8, 0.3}));
  CHECK(t.objects() == 3);
}

TEST_CASE("Fusion::with_weights: a weight per term, DimensionMismatch naming \"weights\" otherwise") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow"), iclap = Fusion::classifier("iclap");
  const Fusion sum = 0.2 * icp + 0.3 * bow + 0.5 * iclap;
  // Too few (even summing to 1), none, too many.
  for (const std::vector<double>& w :
       {std::vector<double>{0.5, 0.5}, std::vector<double>{}, std::vector<double>{0.25, 0.25, 0.25, 0.25}}) {
    CAPTURE(w.size());
    try {
      (void)sum.with_weights(w);
      FAIL("weights of the wrong count were taken");
    } catch (const DimensionMismatch& e) {
      CHECK(e.argument() == "weights");
      CHECK(e.expected() == 3);
      CHECK(e.actual() == static_cast<std::ptrdiff_t>(w.size()));
      CHECK(std::string(e.what()) == "weights: has dimension " + std::to_string(w.size()) + ", expected 3");
    }
  }
  // The right count gives the same sum with the new weights; the original is unchanged.
  const Fusion reweighted = sum.with_weights({0.6, 0.3, 0.1});
  CHECK(reweighted.to_string() == "0.6*icp+0.3*bow+0.1*iclap");
  CHECK(sum.to_string() == "0.2*icp+0.3*bow+0.5*iclap");
  // Only a weighted sum has weights.
  CHECK(error_of([&] { (void)(icp * bow).with_weights({0.5, 0.5}); }) ==
        "weights | weights: only a weighted sum has weights: icp*bow");
}

TEST_CASE("method names, parsing and the weight grid") {
  const auto methods = paper_methods();
  std::vector<std::string> names;
  for (const auto& m : methods) names.push_back(m.name);
  CHECK(names == std::vector<std::string>{"bow", "icp", "iclap", "icp+bow", "icp*bow", "iclap+icp", "iclap*icp",
                                          "iclap+bow", "iclap*bow", "iclap+icp+bow", "iclap*icp*bow"});
  CHECK(!methods[0].fit_weights);
  CHECK(methods[3].fit_weights);
  CHECK(!methods[4].fit_weights);
  CHECK(methods[9].fusion.children().size() == 3);
  const Method fixed = parse_method(" 0.6*iclap + 0.2*icp + 0.2*bow ");
  CHECK(fixed.name == "0.6*iclap+0.2*icp+0.2*bow");
  CHECK(!fixed.fit_weights);
  CHECK(fixed.fusion.weights() == std::vector<double>{0.6, 0.2, 0.2});
  CHECK(error_of([] { parse_method("icp+"); }).find("expected a classifier name") != std::string::npos);
  CHECK(error_of([] { parse_method("0.5*icp+bow"); }).find("for every term") != std::string::npos);
  CHECK(error_of([] { parse_method("(icp"); }).find("missing ')'") != std::string::npos);
  CHECK(error_of([] { parse_method("0.3*icp+0.3*bow"); }).find("sum to 0.6") != std::string::npos);
  CHECK(error_of([] { parse_method("(icp+bow)*iclap"); }).find("top-level") != std::string::npos);
  // Weights are read by from_chars: no silent underflow to 0, no hex.
  CHECK(error_of([] { parse_method("1e-400*icp+1*bow"); }).find("the weight 1e-400 is out of the range of a double") !=
        std::string::npos);
  CHECK(error_of([] { parse_method("0x.8*icp+0x.8*bow"); }) != "(no error)");
  CHECK(parse_method(".5*icp+.5*bow").fusion.weights() == std::vector<double>{0.5, 0.5});
  // Names as with_variants makes them, and names that start with a digit;
  // a space inside a name is an error, not removed.
  const Method variant = parse_method("0.5*patch-trim50 + 0.5*bow");
  CHECK(variant.fusion.weights() == std::vector<double>{0.5, 0.5});
  CHECK(variant.classifiers() == std::vector<std::string>{"patch-trim50", "bow"});
  const Method renamed = with_variants(parse_method("patch+bow"), "patch", {"patch-trim50", "patch-trim100"});
  CHECK(parse_method(renamed.fusion.to_string()).fusion.to_string() == renamed.fusion.to_string());
  CHECK(parse_method("bow+3d").classifiers() == std::vector<std::string>{"bow", "3d"});
  CHECK(error_of([] { parse_method("ic p+bow"); }).find("unexpected 'p+bow' (at character 4)") != std::string::npos);
  CHECK(error_of([] { parse_method("0.5 icp"); }).find("a weight must be followed by '*'") != std::string::npos);
  CHECK(error_of([] { parse_method("-icp"); }).find("expected a classifier name") != std::string::npos);
  // A term given twice: a fitted sum's grid would choose among splits that
  // all give the same fusion, a product ranks as the factor alone does.
  CHECK(error_of([] { parse_method("icp+icp"); }) ==
        "method | method: 'icp+icp': 'icp' appears twice in one sum; give each classifier (or bracketed term) once "
        "(at character 8)");
  CHECK(error_of([] { parse_method("icp+bow+icp"); }).find("'icp' appears twice in one sum") != std::string::npos);
  CHECK(error_of([] { parse_method("iclap*icp*icp"); }).find("'icp' appears twice in one product") !=
        std::string::npos);
  CHECK(error_of([] { parse_method("(0.5*icp+0.5*bow)+(0.5*icp+0.5*bow)"); })
            .find("'0.5*icp+0.5*bow' appears twice in one sum") != std::string::npos);
  // The same term spelt otherwise is the same term (as method_key has it).
  CHECK(error_of([] { parse_method("icp*bow+bow*icp"); }).find("'bow*icp' appears twice in one sum") !=
        std::string::npos);
  CHECK(error_of([] { parse_method("(0.5*icp+0.5*bow)+(0.5*bow+0.5*icp)"); })
            .find("'0.5*bow+0.5*icp' appears twice in one sum") != std::string::npos);
  CHECK(error_of([] { parse_method("iclap*(0.5*icp+0.5*bow)*(0.5*bow+0.5*icp)"); })
            .find("'0.5*bow+0.5*icp' appears twice in one product") != std::string::npos);
  // A term given twice with its weights is the term alone, weighted by their
  // sum: "0.5*icp+0.5*icp" ran as a second column of icp (session 50's
  // audit).
  CHECK(error_of([] { parse_method("0.5*icp+0.5*icp"); }).find("'icp' appears twice in one sum") !=
        std::string::npos);
  CHECK(error_of([] { parse_method("0.2*icp*bow+0.3*bow+0.5*bow*icp"); }).find("'bow*icp' appears twice in one sum") !=
        std::string::npos);
  // A classifier in two different terms is a real fusion.
  CHECK(parse_method("icp*bow+icp").classifiers() == std::vector<std::string>{"icp", "bow"});
  CHECK(parse_method("0.5*icp+0.5*icp*bow").fusion.weights() == std::vector<double>{0.5, 0.5});

  const auto g2 = weight_grid(2);
  REQUIRE(g2.size() == 9);
  CHECK(g2.front() == std::vector<double>{0.1, 0.9});
  const auto g3 = weight_grid(3);
  CHECK(g3.size() == 36);
  for (const auto& w : g3) {
    CHECK(w.size() == 3);
    CHECK(w[0] + w[1] + w[2] == 1.0);
    for (double x : w) CHECK(x >= 0.1 - 1e-12);
  }
  // Beyond the paper: zero weights drop a classifier.
  const auto z2 = weight_grid(2, 10, true);
  REQUIRE(z2.size() == 11);
  CHECK(z2.front() == std::vector<double>{0.0, 1.0});
  CHECK(z2.back() == std::vector<double>{1.0, 0.0});
  const auto z3 = weight_grid(3, 10, true);
  CHECK(z3.size() == 66);
  CHECK(z3.front() == std::vector<double>{0.0, 0.0, 1.0});
  for (const auto& w : z3) CHECK(w[0] + w[1] + w[2] == 1.0);
  CHECK(weight_grid(4, 3, true).size() == 20);
  // weight_grid_size counts the grid without building it.
  for (int terms = 1; terms <= 5; ++terms)
    for (int steps = terms; steps <= 12; ++steps)
      for (const bool zero : {false, true}) {
        CAPTURE(terms);
        CAPTURE(steps);
        CAPTURE(zero);
        CHECK(weight_grid_size(terms, steps, zero) == static_cast<double>(weight_grid(terms, steps, zero).size()));
      }
  CHECK(weight_grid_size(4, 1000, false) == 999.0 * 998.0 * 997.0 / 6.0);
  CHECK_THROWS_AS(weight_grid(2, 0, true), InvalidArgument);
  CHECK(weight_grid(1).size() == 1);
  CHECK_THROWS_AS(weight_grid(4, 3), InvalidArgument);
  // Every grid vector is accepted by the method's sum.
  for (const auto& w : g3) CHECK_NOTHROW(methods[9].fusion.with_weights(w));
  // Also with zero weights and up to 5 terms: a last weight of 0 stays 0
  // (1 - the rounded sum of the others gave -2.2e-16 for 5 terms of tenths,
  // refused by Fusion as negative).
  for (int terms = 2; terms <= 5; ++terms) {
    std::string spec = "c0";
    for (int t = 1; t < terms; ++t) spec += "+c" + std::to_string(t);
    const Fusion fusion = parse_method(spec).fusion;
    for (int steps = terms; steps <= (terms == 5 ? 20 : 30); ++steps) {
      int refused = 0, negative = 0;
      for (bool zero : {false, true})
        for (const auto& w : weight_grid(terms, steps, zero)) {
          for (double x : w) negative += x < 0 ? 1 : 0;
          try {
            (void)fusion.with_weights(w);
          } catch (const InvalidArgument&) {
            ++refused;
          }
        }
      CAPTURE(terms);
      CAPTURE(steps);
      CHECK(negative == 0);
      CHECK(refused == 0);
    }
  }
}

TEST_CASE("method_key: one key for the spellings of one method, distinct keys for distinct methods") {
  const auto key = [](const char* spec) { return method_key(parse_method(spec)); };
  // Sums and products are unordered, at any depth; spaces do not count.
  CHECK(key("icp+bow") == key("bow+icp"));
  CHECK(key("iclap+icp+bow") == key("bow + iclap + icp"));
  CHECK(key("iclap*icp") == key("icp*iclap"));
  CHECK(key("iclap*icp*bow") == key("bow*(icp*iclap)"));  // nested products are flattened
  CHECK(key("0.6*icp+0.4*bow") == key("0.4*bow+0.6*icp"));
  CHECK(key("0.5*(icp*bow)+0.5*iclap") == key("0.5*iclap+0.5*(bow*icp)"));
  CHECK(key("(0.3*icp+0.7*bow)*iclap") == key("iclap*(0.7*bow+0.3*icp)"));
  CHECK(key("icp*bow+iclap") == key("iclap+bow*icp"));
  CHECK(key("1*icp") == key("icp"));
  // Different methods keep different keys: other classifiers, fitted
  // against fixed weights, other fixed weights, a sum against a product,
  // weights moved to other terms, a bracketed sum against the flat one.
  CHECK(key("icp+bow") != key("icp+iclap"));
  CHECK(key("icp+bow") != key("0.5*icp+0.5*bow"));
  CHECK(key("0.6*icp+0.4*bow") != key("0.4*icp+0.6*bow"));
  CHECK(key("0.6*icp+0.4*bow") != key("0.6000001*icp+0.3999999*bow"));
  CHECK(key("icp+bow") != key("icp*bow"));
  CHECK(key("icp") != key("bow"));
  CHECK(key("(0.5*icp+0.5*bow)*iclap") != key("0.5*icp*iclap+0.5*bow*iclap"));
  CHECK(key("iclap+icp+bow") != key("iclap+icp"));
  // Alternatives count, in order.
  const Method m = parse_method("icp+patch");
  CHECK(method_key(with_variants(m, "patch", {"p1", "p2"})) != method_key(m));
  CHECK(method_key(with_variants(m, "patch", {"p1", "p2"})) != method_key(with_variants(m, "patch", {"p2", "p1"})));
}

TEST_CASE("methods with alternatives: renaming and variants") {
  const Method m = parse_method("iclap_patch+patch+bow");
  const Fusion renamed = m.fusion.renamed("patch", "patch-trim50");
  CHECK(renamed.to_string() == "0.3333333333333333*iclap_patch+0.3333333333333333*patch-trim50+0.33333333333333337*bow");
  CHECK(m.fusion.renamed("icp", "x").to_string() == m.fusion.to_string());  // unused: unchanged
  // Every use is renamed (parse_method refuses a repeated factor, the
  // library's product takes it).
  const Fusion icp = Fusion::classifier("icp");
  CHECK((icp * Fusion::classifier("bow") * icp).renamed("icp", "a").to_string() == "a*bow*a");

  // Two classifiers with two variants each: every combination, in order.
  const Method v = with_variants(with_variants(m, "patch", {"p1", "p2"}), "iclap_patch", {"q1", "q2"});
  CHECK(v.name == "iclap_patch+patch+bow");
  CHECK(v.fit_weights);
  std::vector<std::string> candidates;
  for (const auto& c : v.candidates()) candidates.push_back(c.to_string());
  // (Equal weights before fitting: thirds, written so that they read back.)
  const std::string third = "0.3333333333333333*", last = "0.33333333333333337*";
  CHECK(candidates == std::vector<std::string>{third + "q1+" + third + "p1+" + last + "bow",
                                               third + "q2+" + third + "p1+" + last + "bow",
                                               third + "q1+" + third + "p2+" + last + "bow",
                                               third + "q2+" + third + "p2+" + last + "bow"});
  CHECK(v.alternatives.size() == 3);
  CHECK(v.chosen_in_training());
  CHECK(v.classifiers() == std::vector<std::string>{"q1", "p1", "bow", "q2", "p2"});
  CHECK_NOTHROW(v.validate());
  // A method without the classifier is unchanged; an empty list is refused.
  CHECK(with_variants(parse_method("icp"), "patch", {"p1"}).alternatives.empty());
  CHECK(!parse_method("icp").chosen_in_training());
  CHECK(error_of([&] { with_variants(m, "patch", {}); }) == "variants | variants: no variant of classifier 'patch'");
  // A variant twice would make two identical candidates; a variant that is
  // another classifier of the method, a candidate with a repeated term
  // ("bow+bow"). The classifier itself may be one of its variants.
  CHECK(error_of([&] { with_variants(m, "patch", {"p1", "p2", "p1"}); }) ==
        "variants | variants: 'p1' is listed twice among the variants of classifier 'patch'");
  CHECK(error_of([&] { with_variants(m, "patch", {"patch", "bow"}); }) ==
        "variants | variants: 'bow', a variant of classifier 'patch', is already a classifier of method "
        "'iclap_patch+patch+bow'");
  CHECK(with_variants(m, "patch", {"patch", "p1"}).alternatives.size() == 1);
  CHECK(with_variants(parse_method("icp"), "patch", {"icp"}).alternatives.empty());  // patch unused: unchanged
  // Fitted weights need every alternative to be a sum of as many terms.
  Method bad = parse_method("icp+bow");
  bad.alternatives.push_back(Fusion::classifier("icp"));
  CHECK(error_of([&] { bad.validate(); }) ==
        "methods | methods: method 'icp+bow' fits weights, but its alternative icp is not a weighted sum of 2 terms");
}

TEST_CASE("normalisation policies") {
  Eigen::VectorXd d = vec({3, 4, 0});
  normalize(d, Normalization::L2);
  CHECK(d.isApprox(vec({0.6, 0.8, 0.0})));
  d = vec({2, 4, 6});
  normalize(d, Normalization::MinMax);
  CHECK(d.isApprox(vec({0, 0.5, 1})));
  d = vec({1, 2, 3});
  normalize(d, Normalization::ZScore);
  CHECK(d.sum() == doctest::Approx(0.0));
  CHECK(d.squaredNorm() / 3 == doctest::Approx(1.0));
  for (auto kind : {Normalization::L2, Normalization::MinMax, Normalization::ZScore}) {
    Eigen::VectorXd z = vec({0, 0, 0});
    normalize(z, kind);
    CHECK(z.isZero(0));
    Eigen::VectorXd same = vec({5, 5});
    normalize(same, kind);
    CHECK(same.allFinite());
  }
  // All equal: a tie of zeros for MinMax and ZScore, even where the mean
  // rounds off the values (0.1 x 3 sums to 0.30000000000000004; the
  // z-score gave -1 -1 -1).
  for (auto kind : {Normalization::MinMax, Normalization::ZScore})
    for (const double v : {5.0, 0.1, 0.7, 1e-200, 3e200}) {
      Eigen::VectorXd equal = vec({v, v, v});
      normalize(equal, kind);
      CHECK(equal.isZero(0));
    }
  // The z-score is signed: huge negative inputs are scaled like huge
  // positive ones (they gave zeros or NaN), and tiny spreads do not
  // underflow to a tie.
  for (const double scale : {-1e200, 1e-200, -1e-200, 1e300}) {
    d = vec({-2, 1, 1}) * scale;
    normalize(d, Normalization::ZScore);
    REQUIRE(d.allFinite());
    const double sign = scale > 0 ? 1 : -1;
    CHECK(d(0) == doctest::Approx(-sign * std::sqrt(2.0)));
    CHECK(d(1) == doctest::Approx(sign / std::sqrt(2.0)));
  }
  // Distinct distances closer than 1e-150 are not a tie (their squared
  // deviations underflowed: 1e-150 and 1e-150 (1 + 1e-12) gave 0 and 0).
  for (const double base : {1e-146, 1e-150, 1e-151, 1e-300}) {
    CAPTURE(base);
    d = vec({base, base * (1 + 1e-12), base});
    normalize(d, Normalization::ZScore);
    CHECK(d(0) == doctest::Approx(-1 / std::sqrt(2.0)).epsilon(1e-3));
    CHECK(d(1) == doctest::Approx(std::sqrt(2.0)).epsilon(1e-3));
    CHECK(d(2) == d(0));
  }
  d = vec({-1e308, -1e308, 0});
  normalize(d, Normalization::ZScore);
  CHECK(d.isApprox(vec({-1, -1, 2}) / std::sqrt(2.0)));
  // Huge values do not overflow.
  d = vec({1e300, 1e300});
  normalize(d, Normalization::L2);
  CHECK(d(0) == doctest::Approx(std::sqrt(0.5)));
  // Nor in the z-score, whose mean and deviations overflowed to NaN.
  d = vec({1e308, 1.5e308, 1.7e308});
  normalize(d, Normalization::ZScore);
  REQUIRE(d.allFinite());
  CHECK(d.sum() == doctest::Approx(0.0).epsilon(1e-12));
  CHECK(d.squaredNorm() / 3 == doctest::Approx(1.0));
  CHECK(d(0) < d(1));
  CHECK(d(1) < d(2));
  d = vec({1, -1});
  CHECK_THROWS_AS(normalize(d, Normalization::L2), InvalidArgument);
  d = vec({1, std::numeric_limits<double>::quiet_NaN()});
  CHECK_THROWS_AS(normalize(d, Normalization::MinMax), NonFiniteValue);
  CHECK(parse_normalization("minmax") == Normalization::MinMax);
  CHECK_THROWS_AS(parse_normalization("max"), InvalidArgument);
}

TEST_CASE("decision confidence") {
  CHECK(decision_confidence(vec({0.2, 0.4, 0.8})) == doctest::Approx(0.5));
  CHECK(decision_confidence(vec({0.4, 0.4})) == 0.0);
  CHECK(decision_confidence(vec({0.0, 0.4})) == 1.0);
  CHECK(decision_confidence(vec({0.0, 0.0})) == 0.0);
  CHECK(decision_confidence(vec({0.3})) == 1.0);
}

TEST_CASE("weights sum to 1 within 1e-9, and every factor of a product is checked for negative distances") {
  const Fusion icp = Fusion::classifier("icp"), bow = Fusion::classifier("bow"), iclap = Fusion::classifier("iclap");
  // A thousandth off is refused, rounding of tenths is not.
  CHECK(error_of([&] { Fusion f = 0.5 * icp + 0.501 * bow; }) ==
        "weights | weights: the weights sum to 1.001, not 1, in 0.5*icp+0.501*bow");
  CHECK(error_of([&] { Fusion f = 0.5 * icp + 0.4999 * bow; }).find("the weights sum to 0.9999, not 1") !=
        std::string::npos);
  // A sum that six digits would show as 1 is shown with all its digits.
  CHECK(error_of([&] { Fusion f = 0.5 * icp + (0.5 + 1e-8) * bow; }) ==
        "weights | weights: the weights sum to 1.00000001, not 1, in 0.5*icp+0.50000001*bow");
  CHECK(error_of([&] { Fusion f = 0.1 * icp + 0.2 * bow + 0.7 * iclap; }) == "(no error)");
  CHECK(error_of([&] { Fusion f = 0.5 * icp + (0.5 + 1e-10) * bow; }) == "(no error)");
  // A negative distance in the second or a later factor of a product, not
  // only in the first (it gave the product -0.09, which won the decision).
  const auto t = table_of({{"icp", vec({0.7, 0.1})}, {"bow", vec({0.1, -0.9})}, {"iclap", vec({0.5, 0.5})}});
  CHECK(error_of([&] { (icp * bow).evaluate(t); }) ==
        "distances | distances: product fusion needs non-negative distances, but bow has -0.9 (z-score "
        "normalisation is signed: use l2 with products)");
  CHECK(error_of([&] { (iclap * icp * bow).evaluate(t); }).find("but bow has -0.9") != std::string::npos);
  CHECK(error_of([&] { (icp * iclap).evaluate(t); }) == "(no error)");
}

TEST_CASE("min-max normalisation refuses negative distances, as l2 does") {
  for (const auto kind : {Normalization::L2, Normalization::MinMax}) {
    CAPTURE(to_string(kind));
    Eigen::VectorXd d = vec({0.5, -1.0, 2.0});
    CHECK(error_of([&] { normalize(d, kind); }) == std::string("distances | distances: must be non-negative for ") +
                                                         to_string(kind) + " normalisation (got -1)");
    CHECK(d == vec({0.5, -1.0, 2.0}));  // left as it was
    // A tiny negative distance is shown as it is, not as std::to_string's -0.000000.
    Eigen::VectorXd tiny = vec({0.5, -1e-9});
    CHECK(error_of([&] { normalize(tiny, kind); }).find("(got -1e-09)") != std::string::npos);
  }
  Eigen::VectorXd z = vec({0.5, -1.0, 2.0});
  normalize(z, Normalization::ZScore);  // signed by design
  CHECK(z.sum() == doctest::Approx(0.0).epsilon(1e-12));
}

TEST_CASE("normalize builds a name given as a callable only to name an error") {
  // Recognizer passes "distances of 'NAME'" this way for every test: the
  // string is built only when the distances are refused.
  int built = 0;
  const auto name = [&built] {
    ++built;
    return std::string("distances of 'mine'");
  };
  Eigen::VectorXd d = vec({0.5, 1.0, 2.0});
  for (const auto kind : {Normalization::L2, Normalization::MinMax, Normalization::ZScore}) normalize(d, kind, name);
  CHECK(built == 0);
  Eigen::VectorXd negative = vec({0.5, -1.0});
  CHECK(error_of([&] { normalize(negative, Normalization::L2, name); }) ==
        "distances of 'mine' | distances of 'mine': must be non-negative for l2 normalisation (got -1)");
  CHECK(built == 1);
  Eigen::VectorXd nan = vec({0.5, std::numeric_limits<double>::quiet_NaN()});
  CHECK_THROWS_AS(normalize(nan, Normalization::ZScore, name), NonFiniteValue);
  CHECK(built == 2);
}

TEST_CASE("decision confidence: the best and second-best distances wherever they stand") {
  // Descending, the second best last, the best first: 1 - 0.2 / 0.4 each time.
  CHECK(decision_confidence(vec({0.8, 0.4, 0.2})) == doctest::Approx(0.5));
  CHECK(decision_confidence(vec({0.2, 0.9, 0.4})) == doctest::Approx(0.5));
  CHECK(decision_confidence(vec({0.9, 0.2, 0.7, 0.4})) == doctest::Approx(0.5));
  CHECK(decision_confidence(vec({0.4, 0.2})) == doctest::Approx(0.5));
  CHECK(decision_confidence(vec({0.6, 0.6, 0.3})) == doctest::Approx(0.5));
  // Negative fused distances (a z-scored sum) have no relative margin.
  CHECK(error_of([] { decision_confidence(vec({-0.1, 0.5})); }) ==
        "fused | fused: confidence needs non-negative distances");
  CHECK(error_of([] { decision_confidence(vec({0.5, 0.3, -0.2})); }).find("fused | ") == 0);
}

TEST_CASE("an alternative of a fitted method needs as many terms as the method") {
  Method m = parse_method("icp+bow");
  m.alternatives.push_back(parse_method("icp+bow+iclap").fusion);
  CHECK(error_of([&] { m.validate(); }) ==
        "methods | methods: method 'icp+bow' fits weights, but its alternative "
        "0.3333333333333333*icp+0.3333333333333333*bow+0.33333333333333337*iclap is not a weighted sum of 2 terms");
  m.alternatives.back() = parse_method("iclap+bow").fusion;
  CHECK(error_of([&] { m.validate(); }) == "(no error)");
}

TEST_CASE("a recogniser refuses two classifiers of one name") {
  // Their distances would share one entry of the table: the second replaced
  // the first, and a fusion used one of them twice.
  std::vector<std::unique_ptr<Classifier>> cs;
  cs.push_back(std::make_unique<BowClassifier>());
  cs.push_back(std::make_unique<HeightClassifier>());
  cs.push_back(std::make_unique<BowClassifier>());
  CHECK(error_of([&] { Recognizer rec(std::move(cs)); }) ==
        "classifiers | classifiers: two classifiers are named 'bow'");
  std::vector<std::unique_ptr<Classifier>> labelled;
  labelled.push_back(std::make_unique<HeightClassifier>());
  auto second = std::make_unique<HeightClassifier>();
  second->label = "height2";
  labelled.push_back(std::move(second));
  CHECK(error_of([&] { Recognizer rec(std::move(labelled)); }) == "(no error)");
}

TEST_CASE("check_weight_steps: at most 1e6 weight vectors per fitted sum") {
  // 3 terms of at least one step each: C(steps - 1, 2) vectors; 1415 steps
  // give 998991, 1416 give 1000405.
  const Fusion three = parse_method("icp+bow+iclap").fusion;
  CHECK(weight_grid_size(3, 1415, false) == 998991.0);
  CHECK(error_of([&] { check_weight_steps("m", three, 1415, false); }) == "(no error)");
  CHECK(error_of([&] { check_weight_steps("m", three, 1416, false); }) ==
        "weight_steps | weight_steps: is 1416: the grid of the 3 terms of method 'm' "
        "(0.3333333333333333*icp+0.3333333333333333*bow+0.33333333333333337*iclap) has 1.0004e+06 weight vectors, more than 1e+06; lower it");
  // With zero weights: C(steps + 2, 2); 1412 steps give 998991.
  CHECK(error_of([&] { check_weight_steps("m", three, 1412, true); }) == "(no error)");
  CHECK(error_of([&] { check_weight_steps("m", three, 1413, true); }).find("has 1.0004e+06 weight vectors") !=
        std::string::npos);
}

// --- Audit (session 51, helper-47): reproducers of defects, fixed since.

TEST_CASE("audit: decision_confidence refuses a negative distance with one object too, and has none for no object") {
  // Expected: the non-negativity check applies whatever the number of
  // objects (two objects with a negative distance are refused), and an
  // empty vector, which decide() answers with -1 (no object), is no
  // confident decision. Happened: a single negative distance gives
  // confidence 1 without a check, and no object at all gives confidence 1.
  CHECK(error_of([] { decision_confidence(vec({-0.5})); }) == "fused | fused: confidence needs non-negative distances");
  CHECK(decide(Eigen::VectorXd()) == -1);
  CHECK(decision_confidence(Eigen::VectorXd()) != 1.0);
}

TEST_CASE("audit: check_weight_steps refuses a step count that leaves no weight vector with zero weights") {
  // Expected (its doc): InvalidArgument naming "weight_steps" whenever the
  // steps leave no weight vector, as without zero weights. Happened: steps 0
  // or -5 with zero weights pass (weight_grid_has_room is true and the grid
  // "size" is 1 or -4), and weight_grid then throws naming "steps".
  const Fusion two = parse_method("icp+bow").fusion;
  CHECK(error_of([&] { weight_grid(2, 0, true); }).find("steps | ") == 0);  // no vector exists
  for (const int steps : {0, -5}) {
    CAPTURE(steps);
    CHECK(error_of([&] { check_weight_steps("m", two, steps, true); }).find("weight_steps | ") == 0);
  }
}

namespace {
/// A recogniser of the paper's ICP (or BoW) alone, never fitted.
Recognizer unfitted(bool bow) {
  std::vector<std::unique_ptr<Classifier>> cs;
  if (bow) cs.push_back(std::make_unique<BowClassifier>());
  else cs.push_back(std::make_unique<IcpClassifier<double, Planar>>());
  return Recognizer(std::move(cs));
}
}  // namespace

TEST_CASE("audit: an unfitted recogniser refuses to measure, naming itself") {
  // Expected: distances() of a recogniser that was never fitted is refused
  // (as LiveSession refuses it: "recognizer | is not fitted"), naming the
  // recogniser. Happened: with ICP it returns a table of 0 objects, whose
  // decision is -1, silently; with BoW the error names "k", an internal
  // argument of the word histogram ("k: must be at least 1, got 0").
  TouchSet test;
  test.positions = Eigen::Matrix3Xd::Zero(3, 2);
  test.positions(0, 1) = 0.01;
  test.words = WordIds::Zero(2);
  for (const bool bow : {false, true}) {
    CAPTURE(bow);
    const Recognizer rec = unfitted(bow);
    REQUIRE(rec.objects() == 0);
    CHECK(error_of([&] { rec.distances(test); }).find("recognizer | ") == 0);
  }
}

namespace {
/// A classifier of one's own whose pool preparation takes a while, so that
/// the recogniser's workers are all alive at once.
class SlowToPrepare final : public Classifier {
 public:
  explicit SlowToPrepare(int id) : name_("slow" + std::to_string(id)) {}
  std::string name() const override { return name_; }
  void fit(const std::vector<TouchSet>& objects, Index) override { objects_ = static_cast<Index>(objects.size()); }
  void distances(const TouchSet&, Eigen::Ref<Eigen::VectorXd> out) const override { out.setZero(); }
  Index objects() const override { return objects_; }
  std::shared_ptr<const PreparedPool> prepare_pool(const TouchSet&) const override {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return nullptr;
  }

 private:
  std::string name_;
  Index objects_ = 0;
};

/// Whether this build runs under a sanitizer, which reserves more address
/// space than the limit below allows.
constexpr bool kSanitized =
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
    true;
#else
    false;
#endif
#else
    false;
#endif
}  // namespace

TEST_CASE("audit: a worker thread that cannot be started is an error, not std::terminate") {
  // Expected: when the system refuses a worker thread (threads = 64 here,
  // as CrossValidationSettings::threads, which has no upper bound, or
  // Recognizer::prepare_pool's threads), the call throws (std::system_error)
  // or runs on the threads it got. Happened: detail::parallel_for
  // (core/parallel.hpp) lets std::thread's exception leave while the
  // threads already started are joinable, so destroying them calls
  // std::terminate: the process aborts (SIGABRT). The child process below
  // limits its address space so that the third 8 MB thread stack fails.
  if (kSanitized) return;  // the address-space limit would break the sanitizer itself
  const std::string outcome = test::outcome_in_child([] {
    long pages = 0;
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
      std::fclose(f);
    }
    rlimit limit{};
    getrlimit(RLIMIT_AS, &limit);
    limit.rlim_cur = static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE)) + (16u << 20);
    std::vector<std::unique_ptr<Classifier>> cs;
    for (int i = 0; i < 64; ++i) cs.push_back(std::make_unique<SlowToPrepare>(i));
    Recognizer rec(std::move(cs));
    TouchSet one;
    one.positions = Eigen::Matrix3Xd::Zero(3, 1);
    rec.fit({one, one}, 1);
    if (pages == 0 || setrlimit(RLIMIT_AS, &limit) != 0) return std::string("no address-space limit");
    (void)rec.prepare_pool(one, {}, nullptr, 64);
    return std::string("ran");  // on fewer threads: fine
  });
  // Refused with an exception is fine too; a signal (std::terminate) is not.
  CHECK((outcome == "ran" || outcome == "other exception"));
}

TEST_CASE("audit: the text of a fused method reads back as the same method") {
  // Expected: Fusion::to_string (MethodResult::fold_expressions, the
  // "method:" line of iclap live) is a method text that parse_method reads
  // back to the same weights (within the 1e-9 that weighted_sum allows), as
  // it does for the paper's tenths. Happened: weights are written with six
  // digits (format_value), so a grid of thirds (weight_steps = 3, allowed)
  // gives "0.333333*icp+0.333333*bow+0.333333*iclap", refused by
  // parse_method: "the weights sum to 0.999999, not 1".
  const Fusion three = parse_method("icp+bow+iclap").fusion;
  for (const int steps : {3, 6, 9}) {
    for (const auto& w : weight_grid(3, steps)) {
      const Fusion f = three.with_weights(w);
      CAPTURE(f.to_string());
      std::vector<double> back;
      try {
        back = parse_method(f.to_string()).fusion.weights();
      } catch (const InvalidArgument&) {
      }
      REQUIRE(back.size() == 3);
      for (std::size_t i = 0; i < 3; ++i) CHECK(std::abs(back[i] - w[i]) <= 1e-9);
    }
  }
}

TEST_CASE("audit: a classifier name made of digits is a name wherever no '*' follows it") {
  // Expected (parse_method's doc): "a classifier name is letters, digits,
  // '_' and (not first) '-' ... a number is a weight only before '*'", and
  // Fusion::classifier takes "2" and "1e5" as names: so "2", "icp+2" and
  // "1e5+icp" name classifiers "2" and "1e5". Happened: at the start of a
  // term the parser reads the digits as a weight and fails, "a weight must
  // be followed by '*'" (after a weight, "0.5*1e5", and when a letter
  // follows the digits, "3d", they are read as a name).
  CHECK_NOTHROW(Fusion::classifier("2"));
  CHECK(error_of([] { parse_method("3d+icp"); }) == "(no error)");
  CHECK(error_of([] { parse_method("0.5*1e5+0.5*icp"); }) == "(no error)");
  for (const std::string spec : {"2", "icp+2", "1e5+icp"}) {
    CAPTURE(spec);
    CHECK(error_of([&] { parse_method(spec); }) == "(no error)");
  }
  CHECK(parse_method("icp+2").fusion.classifiers() == std::vector<std::string>{"icp", "2"});
  CHECK(parse_method("1e-5 + icp").fusion.classifiers() == std::vector<std::string>{"1e-5", "icp"});
  // Before '*' it is a weight, as before; what cannot be a name still needs
  // its '*', and a '*' needs a number before it.
  CHECK(parse_method("0.5*2+0.5*icp").fusion.weights() == std::vector<double>{0.5, 0.5});
  CHECK(parse_method("1 *icp").fusion.to_string() == "1*icp");
  CHECK(error_of([] { parse_method("0.5+icp"); }).find("a weight must be followed by '*'") != std::string::npos);
  CHECK(error_of([] { parse_method(".*icp"); }).find("expected a classifier name (at character 1)") != std::string::npos);
  // A name never reads as an out-of-range weight; a weight still does.
  CHECK(parse_method("1e999+icp").fusion.classifiers() == std::vector<std::string>{"1e999", "icp"});
  CHECK(error_of([] { parse_method("1e999*icp"); }).find("out of the range of a double") != std::string::npos);
}

TEST_CASE("audit: a product of min-max distances does not decide by index among every factor's best") {
  // Expected: min-max normalisation, which product fusion's error message
  // recommends ("use l2 or minmax with products"), gives products that
  // weigh both factors; or Recognizer::check refuses a product under it as
  // it does under z-score. Happened: min-max puts each classifier's best
  // object at exactly 0, so the product is 0 for every object that any
  // factor ranks first, and the decision among them goes to the smaller
  // index whatever the other factor says: below, icp barely prefers object 0
  // (1.0 against 1.01) and bow strongly prefers object 1, yet object 0 wins;
  // listing the objects the other way round, object 1 (now index 0) wins.
  const Fusion product = Fusion::classifier("icp") * Fusion::classifier("bow");
  Eigen::VectorXd icp = vec({1.0, 1.01, 3.0}), bow = vec({0.9, 0.1, 0.5});
  normalize(icp, Normalization::MinMax);
  normalize(bow, Normalization::MinMax);
  const Index forward = decide(product.evaluate(table_of({{"icp", icp}, {"bow", bow}})));
  const Index backward =
      decide(product.evaluate(table_of({{"icp", vec({icp(1), icp(0), icp(2)})}, {"bow", vec({bow(1), bow(0), bow(2)})}})));
  const bool refused = error_of([] {
                         std::vector<std::unique_ptr<Classifier>> cs;
                         cs.push_back(std::make_unique<BowClassifier>());
                         cs.push_back(std::make_unique<IcpClassifier<double, Planar>>());
                         Recognizer(std::move(cs), Normalization::MinMax).check({parse_method("icp*bow")});
                       }).find("methods | ") == 0;
  // The tie by index that the product would give: object 0 wins in both
  // orders. So Recognizer::check refuses the combination, as under z-score.
  CHECK(forward == 0);
  CHECK(backward == 0);
  CHECK(refused);
  CHECK(error_of([] {
          std::vector<std::unique_ptr<Classifier>> cs;
          cs.push_back(std::make_unique<BowClassifier>());
          cs.push_back(std::make_unique<IcpClassifier<double, Planar>>());
          Recognizer(std::move(cs), Normalization::MinMax).check({parse_method("icp+bow"), parse_method("icp*bow")});
        }).find("methods | methods: method 'icp*bow' multiplies distances, but min-max normalisation puts every "
                "classifier's best object at 0") == 0);
}
