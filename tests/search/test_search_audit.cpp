// SPDX-License-Identifier: MIT
// Reproducers from the session-54 audit (helper h54b) of the search policies,
// the point-cloud traits and the rotation test. Every case failed on the
// code it was written against and was fixed in the same session. Each
// comment says: the input, what happened ("now" at the time), what should
// happen, and the line that caused it.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/point_cloud.hpp"
#include "iclap/core/rotation.hpp"
#include "iclap/search/search.hpp"

using namespace iclap;

// Input: a 3x3 identity whose (2,2) entry (or (1,2), or any entry but
// (0,0)) is NaN, given to orthogonality_deviation.
// Now: it returns 0 (exactly: "is orthogonal"), for Matrix3d, MatrixXd and
// Matrix2d alike; only a NaN at (0,0) gives NaN. Eigen's maxCoeff() uses
// the fast NaN propagation, which drops a NaN unless it is the first
// coefficient.
// Should: return NaN, as the doc comment promises ("0 for an orthogonal q,
// NaN if q holds one"); a caller testing `deviation <= tolerance` now
// accepts a matrix holding a NaN as orthogonal.
// Cause: include/iclap/core/rotation.hpp:23 (`.cwiseAbs().maxCoeff()`).
TEST_CASE("audit: orthogonality_deviation of a matrix holding a NaN is NaN") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix3d q = Eigen::Matrix3d::Identity();
  q(2, 2) = nan;
  CHECK(std::isnan(orthogonality_deviation(q)));  // now 0
  q = Eigen::Matrix3d::Identity();
  q(1, 2) = nan;
  CHECK(std::isnan(orthogonality_deviation(q)));  // now 0
  Eigen::MatrixXd d = Eigen::MatrixXd::Identity(4, 4);
  d(3, 1) = nan;
  CHECK(std::isnan(orthogonality_deviation(d)));  // now 0
  // The scalar rotation_fault then calls the NaN matrix a rotation.
  CHECK(!rotation_fault(orthogonality_deviation(q), 1.0, 1e-3).empty());
}

// Input: rotation_fault / orthogonality_deviation of a 0x0 MatrixXd (a
// square matrix; the empty rotation of dimension 0, determinant 1).
// Now: debug build: Eigen assertion "you are using an empty matrix" aborts
// the program; with -DNDEBUG under -fsanitize=address,undefined:
// "CoreEvaluators.h:207: runtime error: reference binding to null pointer"
// then "AddressSanitizer: SEGV on unknown address 0x000000000000" in
// orthogonality_deviation.
// Should: a number (0: the empty matrix is trivially orthogonal), and
// rotation_fault "" (or, if 0x0 is refused, a reason string) - no crash.
// Cause: include/iclap/core/rotation.hpp:23 (maxCoeff() of an empty matrix).
TEST_CASE("audit: orthogonality_deviation and rotation_fault of a 0x0 matrix do not crash") {
  const Eigen::MatrixXd empty(0, 0);
  CHECK(orthogonality_deviation(empty) == 0.0);  // now: abort / null dereference
  CHECK(rotation_fault(empty, 1e-3).empty());
}

// Input: a search over 3-D points (Eigen::Dynamic or fixed 3) queried with
// a query that is a vector of length dim() only at run time: a 1x3
// Eigen::MatrixXd (a point stored as a row, e.g. `Eigen::MatrixXd q =
// by_rows.row(i)`); and with a 2x2 MatrixXd against a 4-D search.
// Now: check_dimension only compares query.size() with dim(), then
// `const Point<Scalar, Dim> q = query;` assigns a 1x3 (or 2x2) matrix to a
// column vector. Debug build: Eigen assertion in PlainObjectBase::resize /
// resizeLike aborts. -DNDEBUG: for Eigen::Dynamic the vector is resized to
// 1 row, one coordinate is copied and nearest() reads two uninitialised
// ones: the 1x3 query at point 2 answered index 1 (should be 2); the 2x2
// query is silently read as a 4-vector and answered.
// Should: a query of length dim() that is a row or a column is answered
// (as a compile-time row vector already is: `by_rows.row(i)` works), and a
// query that is not a vector (2x2) is refused with DimensionMismatch naming
// "query".
// Cause: include/iclap/search/shared_cloud.hpp:37-38 and
// include/iclap/search/adaptive.hpp:106-107.
TEST_CASE("audit: an Eigen query that is a vector only at run time is read correctly, a matrix is refused") {
  Cloud<double, Eigen::Dynamic> p(3, 4);
  p << 0, 1, 2, 3,  //
      0, 1, 2, 3,   //
      0, 1, 2, 3;
  const Eigen::MatrixXd by_rows = p.transpose();
  const Eigen::MatrixXd row_query = by_rows.row(2);  // 1x3, point 2 itself
  const KdTreeSearch<double> tree(p);
  const BruteForceSearch<double> brute(p);
  const AdaptiveSearch<double> adaptive(p);
  CHECK(tree.nearest(row_query).index == 2);  // now: abort (debug) / 1 (NDEBUG)
  CHECK(brute.nearest(row_query).index == 2);
  CHECK(adaptive.nearest(row_query).index == 2);

  Cloud<double, Eigen::Dynamic> p4 = Cloud<double, Eigen::Dynamic>::Zero(4, 3);
  p4(0, 1) = 1;
  const Eigen::MatrixXd square = Eigen::MatrixXd::Zero(2, 2);  // 4 coefficients, not a vector
  CHECK_THROWS_AS(KdTreeSearch<double>(p4).nearest(square), DimensionMismatch);  // now: abort / answered
  CHECK_THROWS_AS(BruteForceSearch<double>(p4).nearest(square), DimensionMismatch);
  CHECK_THROWS_AS(AdaptiveSearch<double>(p4).nearest(square), DimensionMismatch);
}

// Input: an empty std::vector<Eigen::VectorXd> (points of run-time size)
// given to a search of fixed dimension 3 (KdTreeSearch<double, 3>,
// AdaptiveSearch<float, 3>, ...) or to to_cloud<double, 3>.
// Now: DimensionMismatch "points: has dimension 0, expected 3": the traits
// report dimension 0 for a vector without points, and to_cloud checks it
// against Dim before looking at the size.
// Should: as the doc of to_cloud says, "An empty cloud gives a Cloud
// without columns" (to_cloud<double, 3> of an empty vector of VectorXd is a
// 3x0 cloud, as it already is for an empty vector of Vector3d), and the
// searches refuse it with EmptyInput naming "points" ("has no points"), as
// they do for the Eigen::Dynamic search of the same vector.
// Cause: include/iclap/core/point_cloud.hpp:173 (the dimension check also
// for size 0) with the "0 for no point" dimension of line 64.
TEST_CASE("audit: an empty cloud of run-time-size points is empty, not of dimension 0") {
  const std::vector<Eigen::VectorXd> none;
  CHECK_NOTHROW((to_cloud<double, 3>(none)));  // now: DimensionMismatch
  using Kd3 = KdTreeSearch<double, 3>;
  using Adaptive3f = AdaptiveSearch<float, 3>;
  CHECK_THROWS_AS(Kd3{none}, EmptyInput);  // now: DimensionMismatch
  CHECK_THROWS_AS(Adaptive3f{std::vector<Eigen::VectorXf>{}}, EmptyInput);
  CHECK_THROWS_AS(KdTreeSearch<double>{none}, EmptyInput);  // already so for Eigen::Dynamic
}
