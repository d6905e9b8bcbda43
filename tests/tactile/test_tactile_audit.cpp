// SPDX-License-Identifier: MIT
// Audit of the tactile pipeline from the user's side (session 53, helper-53a).
// Each audit case reproduced a defect (it failed on the code before its
// fix; the moments one was fixed in session 54).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "iclap/search/kdtree.hpp"
#include "iclap/tactile/tactile.hpp"
#include "../support/errors.hpp"

using namespace iclap;

// ---------------------------------------------------------------------------
// Input: KMeansQuantizer<float, Dynamic, KdTreeSearch<float>> with
// settings.k = 2 and settings.search.leaf_max_size = 0 (an invalid search
// setting), features = 4 distinct 2-D points.
// Was: q.check(x) returned normally, but q.fit(x) then threw InvalidArgument
// "settings.leaf_max_size: must be at least 1" (and with pruning on only
// after the whole Lloyd run, at install()). CrossValidation relies on
// check() (cross_validation.hpp:303) to refuse settings before fitting the
// first fold, so such a run fails at its first fit instead.
// Should: check() throws exactly what fit() throws (kmeans.hpp doc of
// check(): "Throws exactly what fit(features) would throw for these features
// and the current settings").
// Cause (fixed: KMeansQuantizer::check_search_settings): kmeans.hpp check and
// check_before_seeding/validate_settings (kmeans.hpp:303) never validate
// settings.search; it is only validated when the Search policy is built in
// run() (kmeans.hpp:497, pruning off) or install() (kmeans.hpp:703).
TEST_CASE("audit: KMeansQuantizer::check() refuses the invalid search settings fit() refuses") {
  KMeansQuantizer<float, Eigen::Dynamic, KdTreeSearch<float>> q;
  q.settings.k = 2;
  q.settings.search.leaf_max_size = 0;
  Eigen::MatrixXf x(2, 4);
  x << 0, 1, 5, 6, 0, 0, 0, 0;
  const std::string from_fit = test::what_of([&] { q.fit(x); });
  CHECK(from_fit == "settings.search.leaf_max_size: must be at least 1");
  CHECK(test::what_of([&] { q.check(x); }) == from_fit);
  // From initial centres too, and a valid setting passes both.
  CHECK(test::what_of([&] { q.fit(x, Eigen::MatrixXf(x.leftCols(2))); }) == from_fit);
  q.settings.search.leaf_max_size = 1;
  CHECK_NOTHROW(q.check(x));
  CHECK_NOTHROW(q.fit(x));
}

// ---------------------------------------------------------------------------
// Input: the same quantizer (settings.search.leaf_max_size = 0), then fit(),
// and from_centres(centres, settings).
// Was: the InvalidArgument named "settings.leaf_max_size", a name the
// KMeansQuantizer user has no such field for (theirs is
// settings.search.leaf_max_size); the error does not name the argument as
// the user wrote it.
// Should: name "settings.search.leaf_max_size" (as k-means' own errors name
// "settings.k", "settings.max_iterations", ...).
// Cause (fixed: KMeansQuantizer::make_search renames it): kdtree.hpp names it relative to the
// search's own Settings, and kmeans.hpp:703 (install) / :497 build the search
// without renaming the argument (e.g. via rename_argument).
TEST_CASE("audit: an invalid KMeansQuantizer search setting is named settings.search.*") {
  using Q = KMeansQuantizer<float, Eigen::Dynamic, KdTreeSearch<float>>;
  Q q;
  q.settings.k = 2;
  q.settings.search.leaf_max_size = 0;
  Eigen::MatrixXf x(2, 4);
  x << 0, 1, 5, 6, 0, 0, 0, 0;
  CHECK(test::argument_of([&] { q.fit(x); }) == "settings.search.leaf_max_size");
  CHECK(test::argument_of([&] { (void)Q::from_centres(Eigen::MatrixXf(x), q.settings); }) ==
        "settings.search.leaf_max_size");
}

// ---------------------------------------------------------------------------
// Input: a 14 x 6 WTS frame with two pressed taxels at opposite corners,
// (0, 0) = 4095 and (13, 5) = 2000 (a two-point / two-edge contact), through
// MomentsDescriptor<double>.
// Was: the Hu entries were [8..14] = 28.7, 826, 1.27e4, 1.27e4, 1.62e8,
// 3.65e5, ~0, while entries 0..7 were all below 1 (a corner taxel plus a
// weak neighbour, 4095 and 400, gave hu[4] = 6.0e8). In Euclidean distance
// entry 12 alone then decided every k-means word.
// Should: as documented in moments.hpp, "position, spread and the invariants
// all have ranges of order 0.1 - 1 and a Euclidean codebook does not ignore
// any of them": every entry of order 1 (checked generously as |f[i]| <= 10).
// Cause (fixed: MomentsDescriptor::compress_invariant): compute() copied the
// raw Hu invariants, polynomials of degree up to 4 in eta_pq = mu_pq /
// u00^(1+(p+q)/2) of the peak-normalised image, where u00 (1.5 here, the
// "area") is tiny beside the spread across the pad.
TEST_CASE("audit: MomentsDescriptor entries stay of order 1 for sparse contacts") {
  const MomentsDescriptor<double> moments;
  Eigen::MatrixXd two_corners = Eigen::MatrixXd::Zero(14, 6);
  two_corners(0, 0) = 4095.0;
  two_corners(13, 5) = 2000.0;
  Eigen::MatrixXd corner_and_neighbour = Eigen::MatrixXd::Zero(14, 6);
  corner_and_neighbour(0, 0) = 4095.0;
  corner_and_neighbour(1, 0) = 400.0;
  for (const Eigen::MatrixXd& p : {two_corners, corner_and_neighbour}) {
    const auto f = moments.compute(TactileImage(p));
    for (int i = 0; i < MomentsDescriptor<double>::kLength; ++i) {
      INFO("entry " << i << " = " << f[i]);
      CHECK(std::abs(f[i]) <= 10.0);
    }
  }
}
