// SPDX-License-Identifier: MIT
// Reproducers from helper-56a's contract audit (session 56) of the
// recognition evaluation layer (cross_validation.hpp, recognizer.hpp,
// bow_classifier.hpp, classifier.hpp). Each case failed before its fix.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "iclap/recognition/recognition.hpp"
#include "fusion_test_util.hpp"
#include "synthetic_objects.hpp"

using namespace iclap;

namespace {

/// A touch set of `n` touches on a line (x = 0.01 i + shift), words `word`.
TouchSet line_set(Index n, double shift, Index word) {
  TouchSet s;
  s.positions.resize(3, n);
  s.words.resize(n);
  for (Index i = 0; i < n; ++i) {
    s.positions.col(i) = Eigen::Vector3d(0.01 * static_cast<double>(i) + shift, 0.002 * static_cast<double>(i % 3), 0);
    s.words(i) = word;
  }
  return s;
}

}  // namespace

// Input: a Recognizer of bow, icp and iclap (test::paper_classifiers) fitted
// on two objects (object 0: words 0, object 1: words 1), then fitted again
// on two other objects (object 0: words 1, object 1: words 0) of which
// object 1 has a NaN position, so that icp's fit throws NonFiniteValue
// after bow's fit has already replaced bow's references.
// Before: the second fit threw, but left bow fitted on the second training
// set and icp / iclap on the first; objects() is still 2, so distances()
// measures without complaint: bow ranks the objects by the new training set
// (a test of words 0 is now nearest object 1, bow distances (1, 0)) while
// icp and iclap rank them by the old one, and a fusion of them silently
// mixes two training sets.
// Now: distances() refuses (InvalidArgument naming "recognizer") until a fit
// succeeds. (Cause: Recognizer::fit refit the classifiers one after another
// with no rollback, and check_fitted asked only the first classifier.)
TEST_CASE("audit: a recogniser whose fit throws does not mix classifiers of two training sets") {
  Recognizer rec(test::paper_classifiers());
  rec.fit({line_set(8, 0.0, 0), line_set(8, 0.05, 1)}, 2);
  const TouchSet test = line_set(3, 0.0, 0);
  const Eigen::VectorXd bow_before = rec.distances(test, {"bow"}).get("bow");
  REQUIRE(bow_before(0) < bow_before(1));

  TouchSet bad = line_set(8, 0.05, 0);
  bad.positions(0, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(rec.fit({line_set(8, 0.0, 1), bad}, 2), NonFiniteValue);

  bool refused = false;
  try {
    rec.distances(test);
  } catch (const InvalidArgument& e) {
    refused = std::string(e.argument()) == "recognizer" &&
              std::string(e.reason()).find("last fit failed") != std::string::npos;
  }
  CHECK(refused);
  // A fit that succeeds makes it usable again, on the new training set.
  rec.fit({line_set(8, 0.0, 1), line_set(8, 0.05, 0)}, 2);
  const Eigen::VectorXd bow_after = rec.distances(test, {"bow"}).get("bow");
  CHECK(bow_after(1) < bow_after(0));
}

// Input: BowClassifier fitted on object 0 (words 0, 0) and object 1 (words
// 1, 1); a test touch set of 1 touch (positions 3 x 1) whose words hold 3
// ids {1, 1, 0} (stale words of another set), or of 0 touches with words
// {1, 1}.
// Before: distances() used every word id and ignored the touches: (0.667,
// 0.333) for the 1-touch test, (1, 0) for the test of no touch; no error.
// The registration classifiers refuse such a set ("touches.words" has
// dimension ..., registration_classifier.hpp:88/230), and the pool path of
// the same classifier (Classifier::pool_distances -> checked_subset ->
// TouchSet::validate_layout) refuses the same words as "pool.words
// (touches)", although its doc says it gives exactly what distances gives.
// Now: DimensionMismatch naming "test.words (touches)" (validate_layout, as
// the pool path), and "objects[j].words (touches)" in fit.
TEST_CASE("audit: the BoW classifier refuses a test whose words are not one per touch") {
  BowClassifier bow;
  bow.fit({line_set(2, 0.0, 0), line_set(2, 0.05, 1)}, 2);
  Eigen::VectorXd d(2);

  TouchSet stale = line_set(1, 0.0, 0);
  stale.words.resize(3);
  stale.words << 1, 1, 0;
  CHECK_THROWS_AS(bow.distances(stale, d), DimensionMismatch);
  CHECK(test::error_of([&] { bow.distances(stale, d); }).find("test.words (touches) | ") == 0);  // was: d = (0.667, 0.333)

  TouchSet none;  // no touch, words left over
  none.words.resize(2);
  none.words << 1, 1;
  CHECK_THROWS(bow.distances(none, d));  // was: d = (1, 0)

  // The fit takes the words of an object's touches only.
  TouchSet object = line_set(2, 0.0, 0);
  object.words.resize(5);
  object.words << 0, 0, 1, 1, 1;
  BowClassifier other;
  CHECK_THROWS_AS(other.fit({object, line_set(2, 0.05, 1)}, 2), DimensionMismatch);
  CHECK(test::error_of([&] { other.fit({object, line_set(2, 0.05, 1)}, 2); }).find("objects[0].words (touches) | ") ==
        0);
}
