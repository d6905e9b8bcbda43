// SPDX-License-Identifier: MIT
// Reproducers from helper-55a's audit (session 55) of the recognition layer
// (fusion, normalisation, method parsing). Each case failed on the code it
// was written against and was fixed in the same session; its comment says
// what happened before ("Now").
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "iclap/recognition/recognition.hpp"
#include "fusion_test_util.hpp"

using namespace iclap;
using iclap::test::error_of;
using iclap::test::vec;

// Input: parse_method("(icp*bow)*icp") and parse_method("icp*(bow*icp)").
// Now: accepted, as the fusion icp*bow*icp (Fusion::product flattens the
// bracketed product), while parse_method("icp*bow*icp"), the same fusion,
// is refused: "'icp' appears twice in one product; give each classifier (or
// bracketed term) once". The README promises a factor given twice in a
// product is refused "also spelt otherwise".
// Should: refuse both bracketed spellings like the plain one.
// Cause: include/iclap/recognition/methods.hpp:248, refuse_repeated compares
// the factors as parsed (icp and the product bow*icp are distinct keys),
// before fusion.hpp:130-131 flattens nested products into one factor list.
TEST_CASE("audit: a classifier given twice in a product is refused whatever the brackets") {
  REQUIRE(error_of([] { parse_method("icp*bow*icp"); }).find("appears twice in one product") != std::string::npos);
  for (const std::string spec : {"(icp*bow)*icp", "icp*(bow*icp)", "iclap*(icp*(bow*icp))"}) {
    CAPTURE(spec);
    CHECK(error_of([&] { parse_method(spec); }).find("appears twice in one product") != std::string::npos);
  }
}

// Input: the product of classifiers "2" and "icp" (parse_method("(2)*icp"),
// or Fusion::classifier("2") * Fusion::classifier("icp")); digit names are
// allowed (README: "A classifier's name may be digits ("2", "1e5")").
// Now: Fusion::to_string gives "2*icp", which parse_method reads as the
// weighted sum 2 x icp and refuses: "weights: the weights sum to 2, not 1,
// in 2*icp". So its MethodResult::fold_expressions / iclap live "method:"
// text does not read back, against the README ("Fusion::to_string writes
// ... so that any fused method's text reads back through parse_method").
// Should: to_string writes such a first factor so that it reads back as a
// name (e.g. "(2)*icp"), giving the same product.
// Cause: include/iclap/recognition/fusion.hpp:217-221 (Product case of
// to_string; to_string_as_factor brackets only weighted sums).
TEST_CASE("audit: a product whose first factor has a digit name reads back through parse_method") {
  const Fusion icp = Fusion::classifier("icp");
  for (const std::string name : {"2", "1e5", "3"}) {
    CAPTURE(name);
    const Fusion product = Fusion::classifier(name) * icp;
    const std::string text = product.to_string();
    CAPTURE(text);
    CHECK(error_of([&] {
            const Method back = parse_method(text);
            CHECK(back.fusion.kind() == Fusion::Kind::Product);
            CHECK(back.fusion.classifiers() == std::vector<std::string>{name, "icp"});
          }) == "(no error)");
    // Inside a weighted sum, and as a later factor.
    const Fusion sum = 0.5 * product + 0.5 * (Fusion::classifier("bow") * Fusion::classifier(name));
    CHECK(parse_method(sum.to_string()).fusion.to_string() == sum.to_string());
  }
  // A name the parser cannot read is refused when made.
  CHECK(error_of([] { (void)Fusion::classifier("-x"); }) ==
        "classifier | classifier: name '-x' may not start with '-'");
}

// Input: a product icp*bow over 3 objects with finite non-negative
// distances icp = (1e-170, 2e-170, 1), bow = (3e-170, 1e-170, 1); the true
// products are 3e-340, 2e-340 and 1, so object 1 is the closest.
// Now: both small products underflow to exactly 0, evaluate gives (0, 0, 1)
// and decide() returns object 0 by the tie rule (smaller index): a false tie
// made by rounding, decided by object order, silently. (The overflow of a
// product is refused, fusion.hpp:177-181 and :198; its underflow is not.)
// Should: a product that ranks the objects as the exact products do (e.g.
// products of mantissas with the exponents summed apart, std::frexp, or a
// rescaling of each factor by its largest entry, which leaves the argmin
// unchanged), or an error when distinct products underflow to a tie.
// Cause: include/iclap/recognition/fusion.hpp:190-199 (out.array() *=
// v.array() at :196 with no guard against underflow).
TEST_CASE("audit: a product of tiny distances does not underflow into a tie decided by index") {
  DistanceTable t;
  t.set("icp", vec({1e-170, 2e-170, 1.0}));
  t.set("bow", vec({3e-170, 1e-170, 1.0}));
  const Fusion product = Fusion::classifier("icp") * Fusion::classifier("bow");
  // The fix refuses it (a double cannot rank 3e-340 against 2e-340).
  CHECK(error_of([&] { (void)product.evaluate(t); }) ==
        "distances | distances: the product icp*bow underflows for object 0 (0): its factors span too many "
        "orders of magnitude to rank the objects; use a weighted sum");
  // A factor of exactly 0 is exact, and small products that stay normal
  // are kept.
  t.set("icp", vec({0.0, 1e-150, 1.0}));
  t.set("bow", vec({1e-300, 1e-150, 1.0}));
  const Eigen::VectorXd fused = product.evaluate(t);
  CHECK(fused(0) == 0.0);
  CHECK(fused(1) == 1e-150 * 1e-150);
  CHECK(decide(fused) == 0);
}

// Input: normalize((1, 1 + 2^-52, 1), ZScore): three distances, one of them
// 1 ulp larger.
// Now: (0, 1.73205, 0): mean 0.577 and population variance 1 about it, not
// the z-score (-0.707, 1.414, -0.707) whose mean is 0. The mean (1 + 2^-52
// / 3) rounds to 1, so the deviations lose the spread's own size. In a
// weighted sum with another z-scored classifier this classifier's gap
// between objects is 18% too small (1.732 instead of 2.121), enough to flip
// a decision. The code already maps spreads below 1e-150 onto [0, 1] for
// this reason (underflow); spreads small relative to the magnitude suffer
// cancellation the same way.
// Should: mean 0 and standard deviation 1 whatever the offset: the z-score
// is shift invariant, so compute it on d - min (exact by Sterbenz for close
// values) or subtract a first-pass mean's residual (two-pass mean).
// Cause: include/iclap/recognition/normalization.hpp:93-95 (mean and
// deviations computed on the unshifted values).
TEST_CASE("audit: z-score of distances a few ulps apart has mean 0 and standard deviation 1") {
  for (const double base : {1.0, 1000.0, 0.1}) {
    CAPTURE(base);
    Eigen::VectorXd d = vec({base, std::nextafter(base, 2 * base), base});
    normalize(d, Normalization::ZScore);
    CAPTURE(d.transpose());
    CHECK(std::abs(d.mean()) < 1e-6);
    CHECK(d.squaredNorm() / 3 == doctest::Approx(1.0));
    CHECK(d(0) == doctest::Approx(-1 / std::sqrt(2.0)));
    CHECK(d(1) == doctest::Approx(std::sqrt(2.0)));
  }
}
