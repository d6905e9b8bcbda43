// SPDX-License-Identifier: MIT
// Behaviour a mutation-testing pass over the registration found unpinned:
// each case fails for at least one single-point change of the library (the
// boundary and the squaring of the distance gate, E and RMSE over the kept
// pairs only, the trimming tie rule, the order and the arithmetic of the
// stopping rules, the inverse and matrix of a transform, the centroid and
// centroid alignment, the composition with an initial rotation, the closed
// 3x3 form's rank flag and its hand-off of near-tied reflections to the
// SVD). A second pass added: trimming after the gate,
// what a registration without pairs reports, given first matches that name
// no reference point or come from a search that rounds its sums
// differently, and the 2-D reflection tie.

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "icp_test_util.hpp"

using namespace iclap;
using namespace iclap::test;

namespace {

/// Pairs of test points 0, 1, ... with the given squared distances.
std::vector<Correspondence<double>> pairs_at(const std::vector<double>& squared) {
  std::vector<Correspondence<double>> pairs;
  for (std::size_t i = 0; i < squared.size(); ++i) pairs.push_back({static_cast<Index>(i), 0, squared[i]});
  return pairs;
}

/// The test indices of the first `kept` pairs, sorted.
std::vector<Index> kept_tests(const std::vector<Correspondence<double>>& pairs, Index kept) {
  std::vector<Index> tests;
  for (Index k = 0; k < kept; ++k) tests.push_back(pairs[static_cast<std::size_t>(k)].test);
  std::sort(tests.begin(), tests.end());
  return tests;
}

/// The rotation by `angle` about coordinate axis `axis` (0: x, 2: z).
Eigen::Matrix3d axis_rotation(int axis, double angle) {
  const Eigen::Vector3d u = Eigen::Vector3d::Unit(axis);
  return Eigen::AngleAxisd(angle, u).toRotationMatrix();
}

/// The origin and the three unit points, one per column.
Eigen::Matrix3Xd origin_and_units() {
  Eigen::Matrix3Xd m(3, 4);
  m << 0, 1, 0, 0,
       0, 0, 1, 0,
       0, 0, 0, 1;
  return m;
}

/// Brute force whose reported squared distance sums the coordinates in
/// reverse order: a user's search policy, exact, but rounding differently
/// from the library's own sums.
struct ReverseSumSearch : BruteForceSearch<double, 4> {
  using BruteForceSearch<double, 4>::BruteForceSearch;
  Neighbor<double> nearest(const double* q) const noexcept {
    Neighbor<double> nb = BruteForceSearch<double, 4>::nearest(q);
    if (nb.index >= 0) nb.squared_distance = reverse_sum(q, points().col(nb.index).data());
    return nb;
  }
  static double reverse_sum(const double* a, const double* b) noexcept {
    double s = 0;
    for (int i = 3; i >= 0; --i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return s;
  }
};

}  // namespace

TEST_CASE("the distance gate compares squared distances and keeps a pair exactly at max_distance") {
  DistanceRejector<double> gate;
  gate.max_distance = 0.5;  // squared 0.25, exactly
  auto pairs = pairs_at({0.25, 0.36, 0.2, 1.0, 0.49});
  const Index kept = gate.select(pairs.data(), 5);
  CHECK(kept == 2);
  CHECK(kept_tests(pairs, kept) == std::vector<Index>{0, 2});
}

TEST_CASE("trimming breaks ties at the boundary by the smaller test index") {
  DistanceRejector<double> trim;
  trim.trim_fraction = 0.5;
  // Six pairs at the same distance, the test indices shuffled: the three
  // kept are those of the smallest test indices, whatever their order.
  std::vector<Correspondence<double>> pairs;
  for (const Index i : {4, 1, 5, 0, 3, 2}) pairs.push_back({i, 0, 1.0});
  const Index kept = trim.select(pairs.data(), 6);
  CHECK(kept == 3);
  CHECK(kept_tests(pairs, kept) == std::vector<Index>{0, 1, 2});
}

TEST_CASE("with rejection, E and RMSE are those of the kept pairs only") {
  // Model: the origin and the three unit points. Test: three points at
  // squared distances 0.01, 0.04 and 0.09 from their partners and one
  // outlier at squared distance 66 from its nearest.
  const Eigen::Matrix3Xd model = origin_and_units();
  Eigen::Matrix3Xd test(3, 4);
  test << 0.1, 1.0, 0.0, 5,
          0.0, 0.2, 0.0, 5,
          0.0, 0.0, 1.3, 5;
  Icp<double, 3, Translation> icp;
  icp.rejection.max_distance = 1.0;
  icp.termination.max_iterations = 0;  // E at the identity
  const auto r = icp.align(ReferenceCloud<double, 3>(model), test);
  CHECK(r.pairs == 3);
  CHECK(r.error == doctest::Approx(0.14).epsilon(1e-12));
  CHECK(r.rmse == doctest::Approx(std::sqrt(0.14 / 3.0)).epsilon(1e-12));
  // Without the gate the outlier counts.
  icp.rejection = {};
  const auto all = icp.align(ReferenceCloud<double, 3>(model), test);
  CHECK(all.pairs == 4);
  CHECK(all.error == doctest::Approx(66.14).epsilon(1e-12));
}

TEST_CASE("the stopping rules: defaults, order and the relative change") {
  PaperTermination<double> term;
  CHECK(term.max_iterations == 50);
  CHECK(term.absolute_tolerance == 0.0);
  CHECK(term.relative_tolerance == 1e-6);
  // Rule order 1, 2, 3: a run whose last allowed update also converged is
  // reported converged, not capped.
  CHECK(term.check(50, 0.0, 1.0) == StopReason::AbsoluteTolerance);
  CHECK(term.check(50, 2.0, 2.0) == StopReason::RelativeTolerance);
  CHECK(term.check(50, 1.0, 2.0) == StopReason::MaxIterations);
  CHECK(term.check(49, 1.0, 2.0) == std::nullopt);
  // The change is relative to the previous error: |1.9 - 1| < 0.5 * 1.9,
  // though not < 0.5 * 1; |2.1 - 1| is not < 0.5 * 2.1.
  term.relative_tolerance = 0.5;
  CHECK(term.check(3, 1.0, 1.9) == StopReason::RelativeTolerance);
  CHECK(term.check(3, 1.0, 2.1) == std::nullopt);
  // Rounding floor: two consecutive errors both at or below it are no
  // change, however far apart relatively; one above it is a change.
  term.relative_tolerance = 1e-6;
  const double floor = 1e-29;
  CHECK(term.check(3, floor, floor / 100, floor) == StopReason::RelativeTolerance);
  CHECK(term.check(3, floor / 100, floor, floor) == StopReason::RelativeTolerance);
  CHECK(term.check(3, floor / 100, 1.5 * floor, floor) == std::nullopt);
  CHECK(term.check(3, 1.5 * floor, floor / 100, floor) == std::nullopt);
  CHECK(term.check(0, floor / 100, floor / 10, floor) == std::nullopt);  // no previous error yet
  CHECK(term.check(3, floor / 100, floor / 10) == std::nullopt);         // the three-argument rules: floor 0
  term.relative_tolerance = 0;                                           // rule 2 off: the floor too
  CHECK(term.check(3, floor / 100, floor / 10, floor) == std::nullopt);
  static_assert(detail::has_floor_check<PaperTermination<double>, double>::value);
  // A relative tolerance must be finite.
  term.relative_tolerance = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(term.validate(), InvalidArgument);
}

TEST_CASE("a transform's inverse, composition, matrix and checked dimensions") {
  RigidTransform<double, 3> T;
  T.R << 0, -1, 0,
         1, 0, 0,
         0, 0, 1;  // a quarter turn about z
  T.t << 1, 2, 3;
  const auto inv = T.inverse();
  CHECK(inv.R == Eigen::Matrix3d(T.R.transpose()));
  CHECK(inv.t == Eigen::Vector3d(-2, 1, -3));  // -(R^T t)
  const auto id = T * inv;
  CHECK(id.R == Eigen::Matrix3d::Identity());
  CHECK(id.t == Eigen::Vector3d::Zero());
  const Eigen::Matrix4d h = T.matrix();
  CHECK(h.topLeftCorner<3, 3>() == T.R);
  CHECK(h.topRightCorner<3, 1>() == T.t);
  CHECK(h.bottomRows<1>() == Eigen::RowVector4d(0, 0, 0, 1));
  using Transform3 = RigidTransform<double, 3>;  // (no comma inside doctest's macros)
  CHECK_THROWS_AS(Transform3::identity(4), DimensionMismatch);
  // At run-time dimension, a translation of the wrong length is refused.
  const RigidTransform<double, Eigen::Dynamic> uneven{Eigen::MatrixXd::Identity(3, 3), Eigen::VectorXd::Zero(4)};
  try {
    uneven.validate(3, "initial");
    FAIL("accepted");
  } catch (const DimensionMismatch& e) {
    CHECK(e.argument() == "initial.t");
  }
}

TEST_CASE("centroid alignment moves the test centroid exactly onto the reference centroid") {
  const Eigen::Matrix3Xd model = origin_and_units();
  Eigen::Matrix3Xd test(3, 4);
  test << 2, 0, 0, 2,
          0, 2, 0, 2,
          0, 0, 2, 2;
  const ReferenceCloud<double, 3> ref(model);
  CHECK(ref.centroid() == Eigen::Vector3d::Constant(0.25));
  Icp<double, 3> icp;
  icp.centroid_alignment = true;
  icp.termination.max_iterations = 0;  // the alignment alone
  const auto r = icp.align(ref, test);
  CHECK(r.iterations == 0);
  CHECK(r.T_model_test.R == Eigen::Matrix3d::Identity());
  CHECK(difference(r.T_model_test.t, Eigen::Vector3d::Constant(-0.75)) < 1e-15);  // 0.25 - 1 per axis
}

TEST_CASE("a planar refinement of a guess with an out-of-plane rotation composes as motion after guess") {
  // T = A T0: the guess T0 tilts about x and shifts; the planar motion A
  // (a turn about z and an (x, y) shift) is applied after it, so
  // R = Rz Rx and t = Rz t0 + a, not Rx Rz or t0 + a.
  const Eigen::MatrixXd model = random_points(3, 200, 17);
  RigidTransform<double, 3> T0{axis_rotation(0, 0.5), Eigen::Vector3d(0.05, -0.04, 0.3)};
  RigidTransform<double, 3> A{axis_rotation(2, 0.1), Eigen::Vector3d(0.02, -0.01, 0.0)};
  const auto T = A * T0;
  const Eigen::MatrixXd test = T.inverse() * model;
  const auto r = Icp<double, 3, Planar>().align(ReferenceCloud<double, 3>(model), test, T0);
  CHECK(r.converged);
  CHECK(difference(r.T_model_test.R, T.R) < 1e-12);
  CHECK(difference(r.T_model_test.t, T.t) < 1e-12);
}

TEST_CASE("the 3x3 closed form flags a singular value below the rank tolerance, as the SVD does") {
  // Singular values 1, 0.5 and 5e-5 under float's rank tolerance (6.1e-5):
  // well enough conditioned for the closed form to answer, rank deficient
  // for the flag.
  const double tol = detail::rank_tolerance<float>(3);
  Rng rng(83);
  for (int k = 0; k < 5; ++k) {
    CAPTURE(k);
    const Eigen::Matrix3d U = random_rotation(3, 3.0, rng), V = random_rotation(3, 3.0, rng);
    const Eigen::Matrix3d H = U * Eigen::Vector3d(1.0, 0.5, 5e-5).asDiagonal() * V.transpose();
    Eigen::Matrix3d R;
    bool degenerate = false;
    REQUIRE(detail::polar_rotation3<double>(H, tol, R, degenerate));
    CHECK(degenerate);
    Eigen::MatrixXd Rd;
    bool by_svd = false;
    detail::proper_rotation<double, Eigen::Dynamic>(Eigen::MatrixXd(H), tol, Rd, by_svd);
    CHECK(by_svd);
    CHECK(difference(R, Rd) < 1e-9);
  }
}

TEST_CASE("the 3x3 closed form leaves a near-tied reflection of axis-aligned pairs to the SVD") {
  // A reflected H whose two smallest singular values are `gap` apart, under
  // float's rank tolerance (6.1e-5). Turned far from the axes, the closed
  // form fails on such an H by itself; aligned with the axes or nearly (a
  // mirror image of axis-aligned pairs), its eigenvectors are exact enough
  // for the refinement to converge, and only the explicit hand-off keeps it
  // from answering "not degenerate" for a tie the SVD flags.
  const double tol = detail::rank_tolerance<float>(3);
  const Eigen::Vector3d a = Eigen::Vector3d(1, 2, 3).normalized(), b = Eigen::Vector3d(3, -1, 2).normalized();
  for (double gap : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
    for (double angle : {0.0, 1e-12, 1e-8, 1e-4}) {
      CAPTURE(gap);
      CAPTURE(angle);
      const Eigen::Matrix3d U = Eigen::AngleAxisd(angle, a).toRotationMatrix();
      const Eigen::Matrix3d V = Eigen::AngleAxisd(-2 * angle, b).toRotationMatrix();
      const Eigen::Matrix3d H = U * Eigen::Vector3d(1.0, 0.01 + gap, -0.01).asDiagonal() * V.transpose();
      const RotationRoutes r = rotation_routes(H, tol);
      CHECK(r.degenerate3 == !(gap > tol));
      CHECK(r.degenerate3 == r.degenerate_dynamic);
      if (!r.degenerate3) CHECK(difference(r.R3, r.Rd) < 1e-9);
    }
  }
}

TEST_CASE("pairs that lose one to the distance gate are no fixed point, even when the rest match as before") {
  // Ten points on the x axis; nine test points sit 0.5 below their partners
  // in z, the tenth 0.5 above. The first update moves all by the mean, +0.4
  // in z: the tenth is then 0.9 from its partner, beyond the gate, and the
  // other nine keep their partners. The nine remaining pairs give +0.5
  // exactly at the next update; stopping there (as if the pairs had not
  // changed) left 0.4 and E = 9 * 0.01.
  Eigen::Matrix3Xd model = Eigen::Matrix3Xd::Zero(3, 10);
  for (Index j = 0; j < 10; ++j) model(0, j) = static_cast<double>(j);
  Eigen::Matrix3Xd test = model;
  test.row(2).setConstant(-0.5);
  test(2, 9) = 0.5;
  Icp<double, 3, Translation> icp;
  icp.rejection.max_distance = 0.8;
  const auto r = icp.align(ReferenceCloud<double, 3>(model), test);
  CHECK(r.pairs == 9);
  CHECK(r.error < 1e-24);
  CHECK(difference(r.T_model_test.t, Eigen::Vector3d(0, 0, 0.5)) < 1e-15);
  CHECK(r.iterations == 2);
}

TEST_CASE("trimming keeps its fraction of the pairs the distance gate left, not of all pairs") {
  DistanceRejector<double> both;
  both.max_distance = 1.0;
  both.trim_fraction = 0.5;
  // Ten pairs, four beyond the gate: half of the six left is three, the
  // closest (test points 2, 5 and 4), not five of ten.
  auto pairs = pairs_at({0.5, 4.0, 0.1, 9.0, 0.3, 0.2, 2.0, 0.9, 3.0, 0.4});
  const Index kept = both.select(pairs.data(), 10);
  CHECK(kept == 3);
  CHECK(kept_tests(pairs, kept) == std::vector<Index>{2, 4, 5});
}

TEST_CASE("without a pair left, a registration reports infinite E and RMSE, a degenerate result and no update") {
  const Eigen::Matrix3Xd model = origin_and_units();
  const Eigen::Matrix3Xd far = (model.array() + 10.0).matrix();
  const ReferenceCloud<double, 3> ref(model);
  Icp<double, 3> icp;
  icp.rejection.max_distance = 1.0;
  IcpWorkspace<double, 3> ws;
  auto run = icp.start(ref, far, nullptr, ws);
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(run.done());
  CHECK(run.pairs() == 0);
  CHECK(run.error() == inf);
  CHECK(run.stop_reason() == StopReason::NoCorrespondences);
  CHECK_FALSE(run.step());
  CHECK(run.iterations() == 0);
  const auto r = run.result();
  CHECK(r.pairs == 0);
  CHECK(r.error == inf);
  CHECK(r.rmse == inf);
  CHECK(r.degenerate);  // no pair determines anything
  CHECK_FALSE(r.converged);
  CHECK(r.T_model_test.R == Eigen::Matrix3d::Identity());
  CHECK(r.T_model_test.t == Eigen::Vector3d::Zero());
}

TEST_CASE("a given first match naming no reference point is refused as such, before its distance is read") {
  const Eigen::MatrixXd model = random_points(3, 100, 81), test = random_points(3, 20, 83);
  const ReferenceCloud<double, 3> ref(model);
  const Icp<double, 3> icp;
  IcpWorkspace<double, 3> ws;
  std::vector<Neighbor<double>> mine;
  icp.first_matches(ref, test, nullptr, ws, mine);
  for (const Index named : {Index(-1), Index(100)}) {  // just below and at the end of the 100 points
    CAPTURE(named);
    std::vector<Neighbor<double>> bad = mine;
    bad[7].index = named;
    try {
      (void)icp.align(ref, test, nullptr, ws, bad);
      FAIL("accepted");
    } catch (const InvalidArgument& e) {
      CHECK(e.argument() == "first_matches");
      CHECK(e.reason() == "entry 7 names reference point " + std::to_string(named) + " of 100");
    }
  }
}

TEST_CASE("given first matches of a search that rounds its sums differently are accepted, as its own would be") {
  // first_matches documents a tolerance for exactly this: the library's
  // check recomputes each distance in its own summation order.
  const Eigen::MatrixXd model = random_points(4, 200, 93), test = random_points(4, 40, 94);
  const ReferenceCloud<double, 4, ReverseSumSearch> ref(model);
  const Icp<double, 4> icp;
  IcpWorkspace<double, 4> ws;
  std::vector<Neighbor<double>> first;
  icp.first_matches(ref, test, nullptr, ws, first);
  // Some reported distances differ from the library's sum in the last bits
  // (otherwise this case could not fail).
  int rounded_differently = 0;
  for (Index i = 0; i < test.cols(); ++i) {
    const auto& nb = first[static_cast<std::size_t>(i)];
    const double own = detail::squared_distance<4>(ws.test_points.col(i).data(),
                                                   ref.working_points().col(nb.index).data(), 4);
    if (own != nb.squared_distance) ++rounded_differently;
  }
  REQUIRE(rounded_differently > 0);
  const auto plain = icp.align(ref, test, nullptr, ws);
  const auto given = icp.align(ref, test, nullptr, ws, first);
  CHECK(given.iterations == plain.iterations);
  CHECK(given.error == plain.error);
  CHECK(given.T_model_test.R == plain.T_model_test.R);
  CHECK(given.T_model_test.t == plain.T_model_test.t);
}

TEST_CASE("a 2-D mirror image leaves the full rigid rotation undetermined: flagged, as in 3-D") {
  // H = diag(1, -1): every proper rotation R gives tr(R H) = 0.
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  const auto tie =
      FullRigid::estimate<double, 2>(zero, zero, Eigen::Matrix2d(Eigen::Vector2d(1, -1).asDiagonal()), 1e-12);
  CHECK(tie.degenerate);
  CHECK(tie.R.determinant() == doctest::Approx(1.0));
  // Distinct singular values: the flipped optimum (the identity) is unique.
  const auto apart =
      FullRigid::estimate<double, 2>(zero, zero, Eigen::Matrix2d(Eigen::Vector2d(2, -1).asDiagonal()), 1e-12);
  CHECK_FALSE(apart.degenerate);
  CHECK(difference(apart.R, Eigen::Matrix2d::Identity()) < 1e-15);
}

TEST_CASE("a maximum distance of 0 is refused as not positive, before its square is judged") {
  DistanceRejector<double> gate;
  gate.max_distance = 0;
  try {
    gate.validate();
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "rejection.max_distance");
    CHECK(e.reason() == "must be > 0 (got 0)");
  }
}

namespace {
/// PaperTermination's rules, recording the rounding floor each check is
/// given (through a pointer: check is const).
template <typename Scalar>
struct FloorRecorder {
  PaperTermination<Scalar> rules;
  std::vector<Scalar>* floors = nullptr;
  void validate() const { rules.validate(); }
  std::optional<StopReason> check(int iterations, Scalar error, Scalar previous_error, Scalar floor) const {
    floors->push_back(floor);
    return rules.check(iterations, error, previous_error, floor);
  }
};

/// Registers a moved, noisy copy of a 10 cm object 30 cm from the origin,
/// trimmed to half its pairs, and checks each floor the registration gave
/// its policy against kept pairs x dimension x (64 eps spread)^2.
template <typename Scalar>
void check_rounding_floor() {
  const Eigen::MatrixXd model = random_points(3, 40, 91, 0.05, 0.3);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(3, 0.02, 0.005, 93, t);
  const Eigen::MatrixXd test = R.transpose() * (model.colwise() - t) + 1e-4 * random_points(3, 40, 95);
  const ReferenceCloud<Scalar, 3> ref(model.cast<Scalar>().eval());
  // The spread is the largest magnitude of a working coordinate: about
  // 5 cm here, whatever the object's distance from the origin.
  CHECK(ref.spread() == static_cast<double>(ref.working_points().cwiseAbs().maxCoeff()));
  CHECK(ref.spread() > 0.03);
  CHECK(ref.spread() < 0.06);
  std::vector<Scalar> floors;
  Icp<Scalar, 3, FullRigid, DistanceRejector<Scalar>, FloorRecorder<Scalar>> icp;
  icp.rejection.trim_fraction = Scalar(0.5);
  icp.termination.floors = &floors;
  const auto r = icp.align(ref, test.cast<Scalar>().eval());
  const Index kept = icp.rejection.trimmed_count(40);
  REQUIRE(r.pairs == kept);  // every iteration keeps the same half of the 40 pairs
  REQUIRE(!floors.empty());
  const double unit = 64 * static_cast<double>(std::numeric_limits<Scalar>::epsilon()) * ref.spread();
  const double expected = static_cast<double>(kept) * 3 * unit * unit;
  // Relative: doctest::Approx's absolute margin (1e-6 * scale 1) would take
  // any floor of these magnitudes (about 1e-11 in float, 1e-29 in double).
  for (const Scalar floor : floors) CHECK(std::abs(static_cast<double>(floor) - expected) <= 1e-6 * expected);
  // Far below this fit's E (noise of 0.1 mm; 1e4 times the floor in float):
  // the floor does not stop it.
  CHECK(static_cast<double>(r.error) > 1e3 * expected);
  CHECK(r.stop_reason == StopReason::RelativeTolerance);
}
}  // namespace

TEST_CASE("the rounding floor a registration gives its policy: kept pairs x dimension x (64 eps spread)^2") {
  check_rounding_floor<float>();
  check_rounding_floor<double>();
}

TEST_CASE("the three-argument stopping rules: an error that rises is a change, the floor being 0") {
  PaperTermination<double> term;
  term.relative_tolerance = 0.5;
  // |1 - 2.1| is not < 0.5 * 1: no stop, though E rose (the floor is 0, so
  // neither error is at or below it).
  CHECK(term.check(3, 2.1, 1.0) == std::nullopt);
  CHECK(term.check(3, 2.1, 1.0, 0.0) == std::nullopt);
  CHECK(term.check(3, 1.2, 1.0) == StopReason::RelativeTolerance);  // |1 - 1.2| < 0.5 * 1
}
