// SPDX-License-Identifier: MIT
// Input validation, rejection, termination, initial transforms, weights and
// the meaning of the reported error.

#include <string>
#include <type_traits>
#include <utility>

#include "../support/errors.hpp"
#include "icp_test_util.hpp"

using namespace iclap;
using namespace iclap::test;

namespace {

/// The error E recomputed from scratch: every transformed test point against
/// every model point, weighted.
double brute_error(const Eigen::MatrixXd& model, const Eigen::MatrixXd& test, const Eigen::MatrixXd& R,
                   const Eigen::VectorXd& t, const Eigen::VectorXd& w) {
  double e = 0;
  for (Index i = 0; i < test.cols(); ++i) {
    const Eigen::VectorXd y = R * test.col(i) + t;
    double best = std::numeric_limits<double>::infinity();
    for (Index j = 0; j < model.cols(); ++j) best = std::min(best, (w.cwiseProduct(y - model.col(j))).squaredNorm());
    e += best;
  }
  return e;
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
using Ref3 = ReferenceCloud<double, 3>;

}  // namespace

TEST_CASE("NaN or Inf anywhere, empty clouds and mismatched dimensions are typed errors naming the argument") {
  const Eigen::MatrixXd model = random_points(3, 20, 1);
  const ReferenceCloud<double, 3> ref(model);
  const Icp<double, 3> icp;

  Eigen::MatrixXd bad = model;
  bad(1, 2) = kNaN;
  try {
    (void)icp.align(ref, bad);
    FAIL("expected NonFiniteValue");
  } catch (const NonFiniteValue& e) {
    CHECK(e.argument() == "test");
    CHECK(e.row() == 1);
    CHECK(e.column() == 2);
  }
  bad(1, 2) = kInf;
  CHECK_THROWS_AS((void)icp.align(ref, bad), NonFiniteValue);
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(bad); }) == "points");
  CHECK_THROWS_AS((void)Ref3(bad), NonFiniteValue);

  CHECK(argument_of([&] { (void)icp.align(ref, Eigen::MatrixXd(3, 0)); }) == "test");
  CHECK_THROWS_AS((void)icp.align(ref, Eigen::MatrixXd(3, 0)), EmptyInput);
  CHECK_THROWS_AS((void)Ref3(Eigen::MatrixXd(3, 0)), EmptyInput);
  CHECK(argument_of([&] { (void)icp.align(ReferenceCloud<double, 3>(), model); }) == "reference");

  CHECK_THROWS_AS((void)icp.align(ref, Eigen::MatrixXd::Zero(4, 5)), DimensionMismatch);
  CHECK(argument_of([&] { (void)icp.align(ref, Eigen::MatrixXd::Zero(4, 5)); }) == "test");
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(Eigen::MatrixXd::Zero(4, 5)); }) == "points");
  const ReferenceCloud<double, Eigen::Dynamic> dref(model);
  CHECK(argument_of([&] { (void)Icp<double, Eigen::Dynamic>().align(dref, Eigen::MatrixXd::Zero(2, 5)); }) == "test");
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(model, Eigen::VectorXd::Ones(2)); }) == "weights");
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(model, Eigen::Vector3d(1, kNaN, 1)); }) == "weights");
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(model, Eigen::Vector3d(1, 0, 1)); }) == "weights");
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(model, Eigen::Vector3d(1, -2, 1)); }) == "weights");
  // The transform divides by the weights: one whose reciprocal overflows
  // (it gave an infinite / NaN transform reported as converged), or one the
  // scalar type cannot hold, is refused.
  CHECK(argument_of([&] { ReferenceCloud<double, 3> r(model, Eigen::Vector3d(1e-310, 1, 1)); }) == "weights");
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(model.cast<float>(), Eigen::Vector3d(1, 1e-40, 1)); }) ==
        "weights");
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(model.cast<float>(), Eigen::Vector3d(1, 1e39, 1)); }) ==
        "weights");
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(model.cast<float>(), Eigen::Vector3d(1e-30, 1, 1e30)); }) ==
        "weights");

  // Finite coordinates whose squared distances overflow the scalar type
  // leave a test point without a neighbour: an error naming the test (it
  // used to index the model with -1), with either search.
  const ReferenceCloud<float, 3> fref(model.cast<float>());
  const ReferenceCloud<float, 3, KdTreeSearch<float, 3>> ftree(model.cast<float>());
  Eigen::Matrix3Xf far = model.cast<float>();
  far(0, 4) = 3e19f;
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(fref, far); }) == "test");
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(ftree, far); }) == "test");
  CHECK(Icp<double, 3>().align(ref, far.cast<double>()).pairs == 20);  // double has the range
  // Beyond largest_coordinate (1.8e15 in float) but squaring to a finite
  // float: the error summed to inf, which no stopping rule could compare,
  // and the run went on to max_iterations. Refused, naming the point.
  far(0, 4) = 1e18f;
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(fref, far); }) == "test");
  const std::string far_message = [&] {
    try {
      (void)Icp<float, 3>().align(ftree, far);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  }();
  CHECK(far_message.find("test: point 4 is at a weighted coordinate of 1e+18") == 0);
  far.row(2).array() += 1e18f;  // every point, in a coordinate the planar model never moves
  CHECK(argument_of([&] { (void)Icp<float, 3, Planar>().align(fref, far); }) == "test");
  far = model.cast<float>();
  far(0, 4) = 1e15f;  // within the range: registered
  CHECK(Icp<float, 3>().align(fref, far).pairs == 20);
  far(0, 4) = 3e19f;

  RigidTransform<double, 3> init = RigidTransform<double, 3>::identity();
  init.R(0, 1) = kNaN;
  CHECK(argument_of([&] { (void)icp.align(ref, model, init); }) == "initial.R");
  init = RigidTransform<double, 3>::identity();
  init.t(2) = kInf;
  CHECK(argument_of([&] { (void)icp.align(ref, model, init); }) == "initial.t");
  // A finite initial transform that moves the (in-range) test beyond what
  // the scalar type can square is at fault, not the test ("test" was
  // named, with either search).
  for (const double t : {1e300, -1e200}) {
    init = RigidTransform<double, 3>::identity();
    init.t(1) = t;
    CHECK(argument_of([&] { (void)icp.align(ref, model, init); }) == "initial");
  }
  init = RigidTransform<double, 3>::identity();
  init.R *= 1e200;  // no rotation: refused before its reach is measured
  CHECK(argument_of([&] { (void)icp.align(ref, model, init); }) == "initial.R");
  RigidTransform<float, 3> finit = RigidTransform<float, 3>::identity();
  finit.t(0) = 1e20f;
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(fref, model.cast<float>(), finit); }) == "initial");
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(ftree, model.cast<float>(), finit); }) == "initial");
  // A test out of range by itself is still the test's fault.
  finit.t(0) = 0.5f;
  CHECK(argument_of([&] { (void)Icp<float, 3>().align(fref, far, finit); }) == "test");
  const RigidTransform<double, Eigen::Dynamic> wrong = RigidTransform<double, Eigen::Dynamic>::identity(4);
  CHECK(argument_of([&] { (void)Icp<double, Eigen::Dynamic>().align(dref, model, wrong); }) == "initial.R rows");

  // A model that needs more coordinates than a run-time cloud has.
  const ReferenceCloud<double, Eigen::Dynamic> flat(random_points(2, 10, 2));
  CHECK(argument_of([&] { (void)Icp<double, Eigen::Dynamic, SpatialRigid>().align(flat, random_points(2, 10, 3)); }) == "test");
  const ReferenceCloud<double, Eigen::Dynamic> line(random_points(1, 10, 2));
  CHECK(argument_of([&] { (void)Icp<double, Eigen::Dynamic, Planar>().align(line, random_points(1, 10, 3)); }) == "test");
}

TEST_CASE("invalid settings are errors naming the setting") {
  const Eigen::MatrixXd model = random_points(3, 20, 1);
  const ReferenceCloud<double, 3> ref(model);
  Icp<double, 3> icp;
  icp.termination.max_iterations = -1;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "termination.max_iterations");
  icp = {};
  icp.termination.relative_tolerance = -0.1;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "termination.relative_tolerance");
  icp = {};
  icp.termination.absolute_tolerance = kNaN;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "termination.absolute_tolerance");
  // +inf stopped every run at its initial transform, "converged".
  icp.termination.absolute_tolerance = std::numeric_limits<double>::infinity();
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "termination.absolute_tolerance");
  icp.termination.absolute_tolerance = -std::numeric_limits<double>::infinity();  // disables rule 1
  CHECK(icp.align(ref, model).converged);
  icp = {};
  icp.rejection.trim_fraction = 0;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "rejection.trim_fraction");
  icp = {};
  icp.rejection.trim_fraction = 1.5;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "rejection.trim_fraction");
  icp = {};
  icp.rejection.max_distance = 0;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "rejection.max_distance");
  // The value is shown exactly: a fraction just above 1 printed as
  // "1.000000", a negative zero as "-0.000000".
  Icp<float, 3> ficp;
  ficp.rejection.trim_fraction = std::nextafter(1.0f, 2.0f);
  CHECK_THROWS_WITH(ficp.rejection.validate(), doctest::Contains("(got 1.0000001)"));
  ficp = {};
  ficp.rejection.max_distance = -0.0f;
  CHECK_THROWS_WITH(ficp.rejection.validate(), doctest::Contains("(got -0)"));
  // A limit whose square underflows would keep only exact matches.
  ficp = {};
  ficp.rejection.max_distance = 1e-23f;
  CHECK_THROWS_WITH(ficp.rejection.validate(), doctest::Contains("must square to a normal number"));
  ficp.rejection.max_distance = 1e-18f;
  CHECK_NOTHROW(ficp.rejection.validate());
  icp = {};
  icp.rejection.max_distance = 1e-160;
  CHECK(argument_of([&] { (void)icp.align(ref, model); }) == "rejection.max_distance");
  icp.rejection.max_distance = 1e-150;
  CHECK_NOTHROW(icp.rejection.validate());
  ficp = {};
  ficp.termination.relative_tolerance = -1e-30f;
  CHECK_THROWS_WITH(ficp.termination.validate(), doctest::Contains("(got -1e-30)"));
}

TEST_CASE("the reported error is E at the returned transform, recomputed by brute force") {
  const Eigen::MatrixXd model = random_points(4, 150, 21);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(4, 0.3, 0.3, 22, t);
  const Eigen::MatrixXd test = (R * random_points(4, 40, 23)).colwise() + t;  // not an exact subset
  const Eigen::Vector4d w(1.0, 2.0, 0.5, 3.0);
  for (int iterations : {0, 1, 5, 50}) {
    Icp<double, 4> icp;
    icp.termination.max_iterations = iterations;
    const auto r = icp.align(ReferenceCloud<double, 4>(model, w), test);
    // The transform of a weighted run is W^-1 R_w W: its error must be
    // measured with the same weights.
    const double expected = brute_error(model, test, r.T_model_test.R, r.T_model_test.t, w);
    CAPTURE(iterations);
    CHECK(r.error == doctest::Approx(expected).epsilon(1e-12));
    CHECK(r.rmse == doctest::Approx(std::sqrt(expected / 40.0)).epsilon(1e-12));
    CHECK(r.pairs == 40);
  }
}

TEST_CASE("weights: a weighted registration is the unweighted one of scaled clouds") {
  const Eigen::MatrixXd model = random_points(4, 120, 31);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<SpatialRigid>(4, 0.1, 0.05, 32, t);
  const Eigen::MatrixXd test = (R.transpose() * (model.colwise() - t));
  const Eigen::Vector4d w(2.0, 2.0, 2.0, 0.25);
  Icp<double, 4, SpatialRigid> icp;
  const auto weighted = icp.align(ReferenceCloud<double, 4>(model, w), test);
  const auto scaled = icp.align(ReferenceCloud<double, 4>(w.asDiagonal() * model), (w.asDiagonal() * test).eval());
  CHECK(weighted.error == doctest::Approx(scaled.error).epsilon(1e-9));
  CHECK(weighted.iterations == scaled.iterations);
  // Uniform weights over the moved block: the rotation is the same, the
  // translation is measured in the scaled units.
  CHECK(difference(weighted.T_model_test.R, scaled.T_model_test.R) < 1e-12);
  CHECK(difference(w.asDiagonal() * weighted.T_model_test.t, scaled.T_model_test.t) < 1e-12);
  CHECK(difference(weighted.T_model_test.R, R) < 1e-12);
}

TEST_CASE("weights steer the matching: a heavy label axis pairs points of the same label") {
  // Two interleaved rows of points with labels 0 and 1, 1 cm apart in y.
  // The test is shifted by 0.6 cm in y: by position alone each test point is
  // closer to the other label's row.
  const Index n = 10;
  Eigen::MatrixXd model(4, 2 * n);
  for (Index i = 0; i < n; ++i) {
    model.col(i) << 0.01 * static_cast<double>(i), 0.0, 0.0, 0.0;
    model.col(n + i) << 0.01 * static_cast<double>(i), 0.01, 0.0, 1.0;
  }
  Eigen::MatrixXd test = model;
  test.row(1).array() += 0.006;
  Icp<double, 4, Translation> icp;
  icp.termination.max_iterations = 0;  // judge only the first matching
  const auto light = icp.align(ReferenceCloud<double, 4>(model, Eigen::Vector4d(1, 1, 1, 1e-4)), test);
  const auto heavy = icp.align(ReferenceCloud<double, 4>(model, Eigen::Vector4d(1, 1, 1, 1.0)), test);
  // Light label: the shifted 0-row pairs with the 1-row 4 mm away (plus a
  // tiny label term); heavy label: every point pairs with its own label, 6 mm away.
  const double nd = static_cast<double>(n);
  CHECK(light.error == doctest::Approx(nd * (0.004 * 0.004 + 1e-8) + nd * 0.006 * 0.006));
  CHECK(heavy.error == doctest::Approx(2 * nd * 0.006 * 0.006));
  // ... and with a free translation, the heavy label recovers the true shift.
  icp.termination.max_iterations = 10;
  const auto fit = icp.align(ReferenceCloud<double, 4>(model, Eigen::Vector4d(1, 1, 1, 1.0)), test);
  CHECK(fit.T_model_test.t(1) == doctest::Approx(-0.006));
}

TEST_CASE("rejection: maximum distance and trimming remove outliers") {
  const Eigen::MatrixXd model = random_points(3, 300, 41);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<SpatialRigid>(3, 0.05, 0.03, 42, t);
  Eigen::MatrixXd test = R.transpose() * (model.leftCols(100).colwise() - t);
  // 10 gross outliers.
  test.rightCols(10) = random_points(3, 10, 43, 1.0, 5.0);
  Icp<double, 3, SpatialRigid> plain;
  const auto biased = plain.align(ReferenceCloud<double, 3>(model), test);
  CHECK(difference(biased.T_model_test.R, R) > 1e-3);

  Icp<double, 3, SpatialRigid> gated;
  gated.rejection.max_distance = 0.5;
  const auto g = gated.align(ReferenceCloud<double, 3>(model), test);
  CHECK(g.pairs == 90);
  CHECK(difference(g.T_model_test.R, R) < 1e-10);

  Icp<double, 3, SpatialRigid> trimmed;
  trimmed.rejection.trim_fraction = 0.85;
  const auto tr = trimmed.align(ReferenceCloud<double, 3>(model), test);
  CHECK(tr.pairs == 85);
  CHECK(difference(tr.T_model_test.R, R) < 1e-10);

  // The count is rounded up: 0.7 * 10 is 7 pairs, not 8.
  DistanceRejector<double> rej;
  rej.trim_fraction = 0.7;
  std::vector<Correspondence<double>> pairs(10);
  for (Index i = 0; i < 10; ++i) pairs[static_cast<std::size_t>(i)] = {i, 0, static_cast<double>(10 - i)};
  CHECK(rej.select(pairs.data(), 10) == 7);
  for (Index k = 0; k < 7; ++k) CHECK(pairs[static_cast<std::size_t>(k)].squared_distance <= 7.0);
}

TEST_CASE("trimming keeps the count the decimal fraction means, in float as in double") {
  // 0.3f is 0.30000001: 0.3f * 10 used to keep 4 pairs where double keeps 3.
  DistanceRejector<float> rf;
  rf.trim_fraction = 0.3f;
  CHECK(rf.trimmed_count(10) == 3);
  CHECK(rf.trimmed_count(160) == 48);
  std::vector<Correspondence<float>> fpairs(10);
  for (Index i = 0; i < 10; ++i) fpairs[static_cast<std::size_t>(i)] = {i, 0, static_cast<float>(10 - i)};
  CHECK(rf.select(fpairs.data(), 10) == 3);

  // Every percentage against exact integer arithmetic, ceil(d n / 100), at
  // least 1, for both scalars; a product just above an integer still
  // rounds up (0.31 * 100 = 31 but 0.31 * 101 = 31.31 keeps 32).
  // Large pair counts too: shrinking the float product by its rounding kept
  // one pair too few from a few hundred thousand pairs on (0.9f of 419439
  // kept 377495).
  DistanceRejector<double> rd;
  Index mismatches = 0;
  auto compare = [&](int d, Index n) {
    const Index want = std::max<Index>(1, (static_cast<Index>(d) * n + 99) / 100);
    if ((rf.trimmed_count(n) != want || rd.trimmed_count(n) != want) && ++mismatches <= 5) {
      CAPTURE(d);
      CAPTURE(n);
      CHECK(rf.trimmed_count(n) == want);
      CHECK(rd.trimmed_count(n) == want);
    }
  };
  for (int d = 1; d < 100; ++d) {
    rf.trim_fraction = static_cast<float>(d) / 100.0f;
    rd.trim_fraction = static_cast<double>(d) / 100.0;
    for (Index n = 1; n <= 5000; ++n) compare(d, n);
    for (const Index n : {Index{419439}, Index{1677727}, Index{4194305}, Index{8388608}, Index{123456789}}) compare(d, n);
  }
  CHECK(mismatches == 0);
  rf.trim_fraction = 0.9f;
  CHECK(rf.trimmed_count(419439) == 377496);
  rf.trim_fraction = 0.31f;
  CHECK(rf.trimmed_count(101) == 32);
  CHECK(rf.trimmed_count(100) == 31);
}

TEST_CASE("no correspondence left is a normal outcome, not an error") {
  const Eigen::MatrixXd model = random_points(3, 50, 51);
  const Eigen::MatrixXd far = model.array() + 100.0;
  Icp<double, 3> icp;
  icp.rejection.max_distance = 1.0;
  const auto r = icp.align(ReferenceCloud<double, 3>(model), far);
  CHECK(!r.converged);
  CHECK(r.stop_reason == StopReason::NoCorrespondences);
  CHECK(r.pairs == 0);
  CHECK(r.error == std::numeric_limits<double>::infinity());
  CHECK(r.T_model_test.R == Eigen::Matrix3d::Identity());
  CHECK(r.T_model_test.t == Eigen::Vector3d::Zero());
  CHECK(std::string(to_string(r.stop_reason)) == "no_correspondences");
}

TEST_CASE("termination: the paper's three rules") {
  const Eigen::MatrixXd model = random_points(3, 200, 61);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(3, 0.3, 0.2, 62, t);
  const Eigen::MatrixXd test = R.transpose() * ((model.leftCols(150) + 0.01 * random_points(3, 150, 63)).colwise() - t);
  const ReferenceCloud<double, 3> ref(model);

  Icp<double, 3> forced;
  forced.termination.max_iterations = 50;
  forced.termination.absolute_tolerance = -1;
  forced.termination.relative_tolerance = 0;
  const auto f = forced.align(ref, test);
  CHECK(f.iterations == 50);
  CHECK(f.stop_reason == StopReason::MaxIterations);
  CHECK(!f.converged);

  Icp<double, 3> none;
  none.termination.max_iterations = 0;
  const auto z = none.align(ref, test);
  CHECK(z.iterations == 0);
  CHECK(z.T_model_test.R == Eigen::Matrix3d::Identity());
  CHECK(z.error == doctest::Approx(brute_error(model, test, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones())));

  Icp<double, 3> loose;
  loose.termination.relative_tolerance = 0.5;
  const auto l = loose.align(ref, test);
  CHECK(l.stop_reason == StopReason::RelativeTolerance);
  CHECK(l.converged);
  CHECK(l.iterations < f.iterations);

  Icp<double, 3> absolute;
  absolute.termination.absolute_tolerance = 1.0;  // E of the start is below this
  absolute.termination.relative_tolerance = 0;
  const auto a = absolute.align(ref, test);
  CHECK(a.stop_reason == StopReason::AbsoluteTolerance);
  CHECK(a.error <= 1.0);

  // An exact fit (error 0 after 0) with rule 1 disabled: rule 2 stops it
  // (0 < 1e-6 * 0 never held, so it ran to max_iterations, not converged).
  Eigen::Matrix3Xd corners(3, 8);  // a box's corners: every sum is exact
  for (int i = 0; i < 8; ++i) corners.col(i) = Eigen::Vector3d(i & 1, 2 * ((i >> 1) & 1), 4 * ((i >> 2) & 1));
  const ReferenceCloud<double, 3> box(corners);
  Icp<double, 3> exact;
  exact.termination.absolute_tolerance = -1;
  const auto e = exact.align(box, corners);
  CHECK(e.error == 0);
  CHECK(e.stop_reason == StopReason::RelativeTolerance);
  CHECK(e.converged);
  CHECK(e.iterations == 1);
  // Rule 2 disabled (relative tolerance 0): an unchanged error does not stop it.
  exact.termination.relative_tolerance = 0;
  exact.termination.max_iterations = 7;
  const auto e0 = exact.align(box, corners);
  CHECK(e0.stop_reason == StopReason::MaxIterations);
  CHECK(e0.iterations == 7);
}

namespace {
/// A trimmed registration of an exact moved copy of `model`, in `Scalar`.
template <typename Scalar, typename Model>
RegistrationResult<Scalar, 3> trimmed_exact_copy(const Eigen::MatrixXd& model, double trim, int max_iterations,
                                                 double relative_tolerance, Eigen::MatrixXd& R, Eigen::VectorXd& t) {
  R = random_motion<Model>(3, 0.02, 0.005, 71, t);
  const Eigen::MatrixXd test = R.transpose() * (model.colwise() - t);  // model = R test + t
  const ReferenceCloud<Scalar, 3> ref(model.cast<Scalar>().eval());
  Icp<Scalar, 3, Model> icp;
  icp.rejection.trim_fraction = static_cast<Scalar>(trim);
  icp.termination.max_iterations = max_iterations;
  icp.termination.relative_tolerance = static_cast<Scalar>(relative_tolerance);
  return icp.align(ref, test.cast<Scalar>().eval());
}
}  // namespace

TEST_CASE_TEMPLATE("termination: a trimmed registration of an exact copy converges at the rounding floor", Scalar,
                   float, double) {
  // Every pair of an exact fit is at rounding distance, and trimming keeps
  // a different closest fraction of them at each step: E jumped between
  // values such as 1e-32 and 1e-34 (double), so its relative change never
  // fell below 1e-6, and the registration ran to max_iterations, reported
  // not converged. Two consecutive errors at or below the rounding floor
  // are now no change (rule 2).
  const Eigen::MatrixXd model = random_points(3, 60, 73, 0.05, 0.3);  // a 10 cm object 30 cm from the origin
  Eigen::MatrixXd R;
  Eigen::VectorXd t;
  for (const double trim : {0.9, 0.5}) {
    CAPTURE(trim);
    const auto fp = trimmed_exact_copy<Scalar, FullRigid>(model, trim, 50, 1e-6, R, t);
    const auto pl = trimmed_exact_copy<Scalar, Planar>(model, trim, 50, 1e-6, R, t);
    for (const auto* r : {&fp, &pl}) {
      CHECK(r->converged);
      CHECK(r->stop_reason == StopReason::RelativeTolerance);
      CHECK(r->iterations < 10);
      // The fit is exact to rounding: the floor is 64 units in the last
      // place of the 5 cm spread per coordinate.
      CHECK(r->rmse <= 64 * std::sqrt(3.0) * 0.05 * std::numeric_limits<Scalar>::epsilon());
    }
    // The recovered motion is the true one (Planar's last: its R and t).
    CHECK(difference(pl.T_model_test.R, R) < eps<Scalar>(1e3));
    CHECK(difference(pl.T_model_test.t, t) < eps<Scalar>(1e3));
    // With rule 2 disabled (relative tolerance 0), the floor does not stop
    // it either: max_iterations forces every iteration.
    const auto forced = trimmed_exact_copy<Scalar, Planar>(model, trim, 7, 0, R, t);
    CHECK(forced.stop_reason == StopReason::MaxIterations);
    CHECK(forced.iterations == 7);
  }
}

namespace {
/// A user's termination policy with the three-argument check only: stops
/// after `cap` updates, whatever E does.
struct CappedTermination {
  int cap = 3;
  void validate() const {}
  std::optional<StopReason> check(int iterations, double, double) const {
    if (iterations >= cap) return StopReason::MaxIterations;
    return std::nullopt;
  }
};
static_assert(!detail::has_floor_check<CappedTermination, double>::value);
}  // namespace

TEST_CASE("a termination policy without the rounding floor is called with three arguments") {
  const Eigen::MatrixXd model = random_points(3, 60, 73, 0.05, 0.3);
  Eigen::MatrixXd R;
  Eigen::VectorXd t;
  R = random_motion<Planar>(3, 0.02, 0.005, 71, t);
  const Eigen::MatrixXd test = R.transpose() * (model.colwise() - t);
  const ReferenceCloud<double, 3> ref(model);
  Icp<double, 3, Planar, DistanceRejector<double>, CappedTermination> icp;
  icp.rejection.trim_fraction = 0.9;
  const auto r = icp.align(ref, test);
  CHECK(r.iterations == 3);  // the policy alone decides, though the copy is exact
  CHECK(r.stop_reason == StopReason::MaxIterations);
}

TEST_CASE("the iterations reuse the workspace's buffers from the first step on") {
  // Both pair buffers are sized when a registration starts: the steps only
  // swap them (the first step used to size the second one).
  const Eigen::Matrix3Xd model = random_points(3, 60, 41);
  const ReferenceCloud<double, 3> ref(model);
  const Icp<double, 3> icp;
  Icp<double, 3>::Workspace ws;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3Xd test = (turn * model).colwise() + Eigen::Vector3d(0.01, 0.0, 0.0);
  auto reg = icp.start(ref, test, nullptr, ws);
  const auto* a = ws.pairs.data();
  const auto* b = ws.previous_pairs.data();
  REQUIRE(a != nullptr);
  REQUIRE(b != nullptr);
  int steps = 0;
  while (steps < 5 && reg.step()) {
    ++steps;
    const bool same = (ws.pairs.data() == a && ws.previous_pairs.data() == b) ||
                      (ws.pairs.data() == b && ws.previous_pairs.data() == a);
    CHECK(same);
  }
  CHECK(steps > 0);
}

TEST_CASE("an initial guess that is no rotation is refused naming initial.R; rotations and weighted results pass") {
  const Eigen::MatrixXd model = random_points(4, 120, 91);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(4, 0.2, 0.1, 92, t);
  const Eigen::MatrixXd test = R.transpose() * (model.colwise() - t);
  const ReferenceCloud<double, 4> ref(model);
  const Icp<double, 4> icp;
  using T4 = RigidTransform<double, 4>;

  // The exact answer passes (and is kept); so does any rotation.
  const auto exact = icp.align(ref, test, T4{R, t});
  CHECK(exact.error < 1e-20);
  CHECK(what_of([&] { (void)icp.align(ref, test, T4{R.transpose(), t}); }) == "(no error)");

  T4 bad{R, t};
  bad.R *= 1.01;  // scaled
  const std::string scaled = what_of([&] { (void)icp.align(ref, test, bad); });
  CHECK(scaled.find("initial.R: is not orthogonal: the largest entry of |R^T R - I| is 0.0201") == 0);
  CHECK(argument_of([&] { (void)icp.align(ref, test, bad); }) == "initial.R");
  bad.R = R;
  bad.R.col(2) *= -1.0;  // a reflection
  CHECK(what_of([&] { (void)icp.align(ref, test, bad); }).find("initial.R: is orthogonal with det -1 (a reflection)") ==
        0);
  bad.R = R;
  bad.R(0, 1) += 0.01;  // sheared
  CHECK(argument_of([&] { (void)icp.align(ref, test, bad); }) == "initial.R");
  bad.R = Eigen::Matrix4d::Identity();
  bad.R(3, 3) = 16.0;  // det 16, one coordinate only
  CHECK(argument_of([&] { (void)icp.align(ref, test, bad); }) == "initial.R");
  bad.R(3, 3) = 0.0;  // singular
  CHECK(argument_of([&] { (void)icp.align(ref, test, bad); }) == "initial.R");
  // Within the tolerance (a rotation typed to six decimals) is accepted.
  bad.R = (R * 1e6).array().round() / 1e6;
  CHECK(what_of([&] { (void)icp.align(ref, test, bad); }) == "(no error)");

  // A weighted reference's result is W^-1 Q W, no orthogonal matrix: fed
  // back as the guess of the same reference it passes and is already the
  // answer; a plain rotation passes too.
  const Eigen::Vector4d w(1.0, 1.0, 1.0, 3.0);
  const ReferenceCloud<double, 4> weighted(model, w);
  const Eigen::MatrixXd Rw = w.cwiseInverse().asDiagonal() * R * w.asDiagonal();
  const Eigen::MatrixXd wtest = Rw.inverse() * (model.colwise() - t);
  const auto first = icp.align(weighted, wtest);
  CHECK(first.error < 1e-16);
  CHECK(difference(first.T_model_test.R.transpose() * first.T_model_test.R, Eigen::Matrix4d::Identity()) > 0.01);
  CHECK(difference(first.T_model_test.R, Rw) < 1e-9);
  const auto again = icp.align(weighted, wtest, first.T_model_test);
  CHECK(again.error <= first.error * (1 + 1e-9) + 1e-20);
  CHECK(what_of([&] { (void)icp.align(weighted, test, T4{R, t}); }) == "(no error)");
  // The same W^-1 Q W for unit weights is no rotation.
  CHECK(argument_of([&] { (void)icp.align(ref, test, first.T_model_test); }) == "initial.R");

  // A run-time dimension of 40 whose guess rotates two coordinates.
  const Eigen::MatrixXd big = random_points(40, 60, 93);
  const ReferenceCloud<double, Eigen::Dynamic> dref(big);
  RigidTransform<double, Eigen::Dynamic> yaw = RigidTransform<double, Eigen::Dynamic>::identity(40);
  yaw.R.topLeftCorner<2, 2>() << 0.6, -0.8, 0.8, 0.6;
  CHECK(what_of([&] { (void)Icp<double, Eigen::Dynamic>().align(dref, big, yaw); }) == "(no error)");
  yaw.R(39, 39) = -1.0;
  CHECK(argument_of([&] { (void)Icp<double, Eigen::Dynamic>().align(dref, big, yaw); }) == "initial.R");
  // float: a rotation rounded to float passes.
  const ReferenceCloud<float, 4> fref(model.cast<float>());
  const RigidTransform<float, 4> fguess{R.cast<float>(), t.cast<float>()};
  CHECK(what_of([&] { (void)Icp<float, 4>().align(fref, test.cast<float>().eval(), fguess); }) == "(no error)");
}

TEST_CASE("initial transform and centroid alignment") {
  const Eigen::MatrixXd model = random_points(3, 200, 71);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(3, 0.05, 0.0, 72, t);
  const Eigen::Vector3d far_shift(4.0, -3.0, 2.0);  // far outside the basin
  const Eigen::MatrixXd test = R.transpose() * (model.colwise() - far_shift);
  const ReferenceCloud<double, 3> ref(model);

  Icp<double, 3> aligned;
  aligned.centroid_alignment = true;
  const auto found = aligned.align(ref, test);
  CHECK(difference(found.T_model_test.R, R) < 1e-10);
  CHECK(difference(found.T_model_test.t, far_shift) < 1e-10);

  RigidTransform<double, 3> guess{Eigen::Matrix3d::Identity(), far_shift};
  const auto guided = Icp<double, 3>().align(ref, test, guess);
  CHECK(difference(guided.T_model_test.R, R) < 1e-10);
  CHECK(difference(guided.T_model_test.t, far_shift) < 1e-10);

  // The exact answer as the guess: nothing to do.
  RigidTransform<double, 3> exact{R, far_shift};
  const auto done = Icp<double, 3>().align(ref, test, exact);
  CHECK(done.error < 1e-20);
  CHECK(done.iterations <= 3);  // rounding-level updates until E stops changing

  // A planar refinement keeps the out-of-plane part of the guess.
  RigidTransform<double, 3> lifted{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.5)};
  const auto planar = Icp<double, 3, Planar>().align(ref, model, lifted);
  CHECK(planar.T_model_test.t(2) == doctest::Approx(0.5));
}

namespace {
// Whether `icp.start(reference, ...)` compiles for a reference of type Ref.
template <typename Ref, typename = void>
struct can_start : std::false_type {};
template <typename Ref>
struct can_start<Ref, std::void_t<decltype(std::declval<const Icp<double, 4, SpatialRigid>&>().start(
                          std::declval<Ref>(), std::declval<const Eigen::MatrixXd&>(), nullptr,
                          std::declval<IcpWorkspace<double, 4>&>()))>> : std::true_type {};
// The registration keeps a pointer to its reference: a temporary does not compile.
static_assert(can_start<const ReferenceCloud<double, 4>&>::value);
static_assert(!can_start<ReferenceCloud<double, 4>>::value);
}  // namespace

TEST_CASE("a resumable registration matches align and never increases the error") {
  const Eigen::MatrixXd model = random_points(4, 150, 81);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(4, 0.3, 0.3, 82, t);
  const Eigen::MatrixXd test = (R * random_points(4, 60, 83)).colwise() + t;
  const ReferenceCloud<double, 4> ref(model);
  Icp<double, 4, SpatialRigid> icp;
  icp.termination.max_iterations = 40;
  IcpWorkspace<double, 4> ws;
  auto run = icp.start(ref, test, nullptr, ws);
  CHECK(run.iterations() == 0);
  double previous = run.error();
  CHECK(std::isfinite(previous));
  int steps = 0;
  while (run.step()) {
    ++steps;
    CHECK(run.error() <= previous * (1 + 1e-12));  // monotone without rejection
    previous = run.error();
  }
  CHECK(run.done());
  CHECK(!run.step());  // a no-op once done
  const auto resumed = run.result();
  const auto direct = icp.align(ref, test);
  CHECK(resumed.iterations == direct.iterations);
  CHECK(resumed.error == direct.error);
  CHECK(resumed.T_model_test.R == direct.T_model_test.R);
  CHECK(resumed.T_model_test.t == direct.T_model_test.t);
  CHECK(resumed.stop_reason == direct.stop_reason);
  CHECK(resumed.degenerate == direct.degenerate);
  // Interleaving two registrations with their own workspaces changes nothing.
  IcpWorkspace<double, 4> ws_a, ws_b;
  auto a = icp.start(ref, test, nullptr, ws_a);
  auto b = icp.start(ref, (test * 1.0).eval(), nullptr, ws_b);
  while (!a.done() || !b.done()) {
    a.step();
    b.step();
  }
  CHECK(a.result().error == direct.error);
  CHECK(b.result().error == direct.error);
  // Trimmed ICP is monotone too (the pruning of the trimmed classifiers
  // relies on it); a distance cut-off is not, and nothing relies on that.
  for (double fraction : {0.3, 0.5, 0.8}) {
    Icp<double, 4, SpatialRigid> trimmed = icp;
    trimmed.rejection.trim_fraction = fraction;
    IcpWorkspace<double, 4> ws_t;
    auto tr = trimmed.start(ref, test, nullptr, ws_t);
    CHECK(tr.pairs() == static_cast<Index>(std::ceil(fraction * 60 - 1e-9)));
    const double first = tr.error();
    double before = first;
    int trimmed_steps = 0;
    while (tr.step()) {
      ++trimmed_steps;
      CHECK(tr.error() <= before * (1 + 1e-12));
      before = tr.error();
    }
    CHECK(trimmed_steps >= 2);
    CHECK(tr.error() < first);  // the steps did lower the error
  }
}

namespace {
/// Brute force that counts its queries (a search policy of the user's kind).
struct CountingSearch : BruteForceSearch<double, 3> {
  using BruteForceSearch<double, 3>::BruteForceSearch;
  static inline long long queries = 0;
  Neighbor<double> nearest(const double* q) const noexcept {
    ++queries;
    return BruteForceSearch<double, 3>::nearest(q);
  }
};

/// 60 of `model`'s points, moved a little (the query-counting cases).
Eigen::MatrixXd counted_test(const Eigen::MatrixXd& model) {
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<FullRigid>(3, 0.1, 0.05, 62, t);
  return R.transpose() * (model.leftCols(60).colwise() - t);
}
}  // namespace

TEST_CASE("a fixed point of the matching ends the search, not the iteration count") {
  // Once the pairs matched under a transform are those it was estimated
  // from, the next update reproduces it; that iteration is counted and the
  // rules checked, but nobody searches again.
  const Eigen::MatrixXd model = random_points(3, 200, 61), test = counted_test(model);
  const ReferenceCloud<double, 3, CountingSearch> ref(model);
  Icp<double, 3> icp;
  CountingSearch::queries = 0;
  const auto converged = icp.align(ref, test);
  REQUIRE(converged.stop_reason == StopReason::RelativeTolerance);
  // One matching before the first update and one after each update but the
  // last, which met the fixed point.
  CHECK(CountingSearch::queries == 60LL * converged.iterations);
  // The same registration without the relative rule runs to the cap without
  // searching after the fixed point, and ends where the converged one did.
  icp.termination.relative_tolerance = 0;
  icp.termination.max_iterations = 200;
  CountingSearch::queries = 0;
  const auto capped = icp.align(ref, test);
  CHECK(capped.stop_reason == StopReason::MaxIterations);
  CHECK(capped.iterations == 200);
  CHECK(CountingSearch::queries == 60LL * converged.iterations);
  CHECK(capped.error == converged.error);
  CHECK(capped.T_model_test.R == converged.T_model_test.R);
  CHECK(capped.T_model_test.t == converged.T_model_test.t);
  // And the kd-tree, which uses its own warm-started queries, agrees.
  icp.termination = {};
  const auto tree = icp.align(ReferenceCloud<double, 3, KdTreeSearch<double, 3>>(model), test);
  CHECK(tree.iterations == converged.iterations);
  CHECK(tree.error == converged.error);
  CHECK(tree.T_model_test.R == converged.T_model_test.R);
}

namespace {
/// The entries of `pool_matches` of the pool columns `subset`.
template <typename Scalar>
std::vector<Neighbor<Scalar>> gather(const std::vector<Neighbor<Scalar>>& pool_matches,
                                     const std::vector<Index>& subset) {
  std::vector<Neighbor<Scalar>> out;
  for (Index i : subset) out.push_back(pool_matches[static_cast<std::size_t>(i)]);
  return out;
}

template <typename Icp, typename Ref, typename Transform>
void check_pool_subsets(const Icp& icp, const Ref& ref, const Eigen::MatrixXf& pool, const Transform* initial) {
  using Ws = typename Icp::Workspace;
  Ws ws;
  std::vector<Neighbor<float>> matches;
  icp.first_matches(ref, pool, initial, ws, matches);
  REQUIRE(matches.size() == static_cast<std::size_t>(pool.cols()));
  Rng rng(91);
  for (Index n : {1, 2, 5, 13, 40}) {
    std::vector<Index> subset;
    for (Index i = 0; i < pool.cols(); ++i) subset.push_back(i);
    for (Index i = 0; i < n; ++i) {  // partial Fisher-Yates
      const auto j = i + static_cast<Index>(rng.below(static_cast<std::uint64_t>(pool.cols() - i)));
      std::swap(subset[static_cast<std::size_t>(i)], subset[static_cast<std::size_t>(j)]);
    }
    subset.resize(static_cast<std::size_t>(n));
    Eigen::MatrixXf test(pool.rows(), n);
    for (Index k = 0; k < n; ++k) test.col(k) = pool.col(subset[static_cast<std::size_t>(k)]);
    CAPTURE(n);
    Ws a, b;
    const auto plain = icp.align(ref, test, initial, a);
    const auto given = icp.align(ref, test, initial, b, gather(matches, subset));
    CHECK(given.iterations == plain.iterations);
    CHECK(given.stop_reason == plain.stop_reason);
    CHECK(given.pairs == plain.pairs);
    CHECK(given.error == plain.error);
    CHECK(given.T_model_test.R == plain.T_model_test.R);
    CHECK(given.T_model_test.t == plain.T_model_test.t);
  }
}
}  // namespace

TEST_CASE("first matches computed once for a pool leave its subsets' registrations unchanged") {
  // Cross validation registers many subsets of one held-out exploration
  // against the same reference: each point's first match does not depend on
  // the other points, so it is searched once for the pool.
  const Eigen::MatrixXf model = random_points(4, 300, 71).cast<float>();
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<Planar>(4, 0.2, 0.1, 72, t);
  const Eigen::MatrixXd near = random_points(4, 40, 73) * 0.8;
  const Eigen::MatrixXf pool = (R.transpose() * (near.colwise() - t)).cast<float>();
  const ReferenceCloud<float, 4> ref(model, Eigen::Vector4f(1, 1, 1, 0.3f));
  Icp<float, 4, Planar> planar;
  check_pool_subsets(planar, ref, pool, static_cast<const RigidTransform<float, 4>*>(nullptr));
  RigidTransform<float, 4> T0 = RigidTransform<float, 4>::identity(4);
  T0.R.topLeftCorner<2, 2>() << 0.8f, -0.6f, 0.6f, 0.8f;
  T0.t << 0.05f, -0.02f, 0, 0;
  check_pool_subsets(planar, ref, pool, &T0);
  Icp<float, 4, FullRigid> trimmed;  // the rejector sees the given pairs like searched ones
  trimmed.rejection.trim_fraction = 0.6f;
  trimmed.rejection.max_distance = 1.5f;
  check_pool_subsets(trimmed, ReferenceCloud<float, 4, BruteForceSearch<float, 4>>(model), pool,
                     static_cast<const RigidTransform<float, 4>*>(nullptr));
}

TEST_CASE("given first matches skip exactly the first round of queries") {
  const Eigen::MatrixXd model = random_points(3, 200, 61), test = counted_test(model);
  const ReferenceCloud<double, 3, CountingSearch> ref(model);
  Icp<double, 3> icp;
  IcpWorkspace<double, 3> ws;
  std::vector<Neighbor<double>> first;
  CountingSearch::queries = 0;
  icp.first_matches(ref, test, nullptr, ws, first);
  CHECK(CountingSearch::queries == 60);
  CountingSearch::queries = 0;
  const auto plain = icp.align(ref, test, nullptr, ws);
  const long long plain_queries = CountingSearch::queries;
  CountingSearch::queries = 0;
  const auto given = icp.align(ref, test, nullptr, ws, first);
  CHECK(CountingSearch::queries == plain_queries - 60);
  CHECK(given.error == plain.error);
  CHECK(given.iterations == plain.iterations);
  // start() takes them as well.
  CountingSearch::queries = 0;
  auto run = icp.start(ref, test, nullptr, ws, first);
  CHECK(CountingSearch::queries == 0);
  run.run();
  CHECK(run.result().error == plain.error);
}

TEST_CASE("first matches that do not belong to the registration are refused") {
  const Eigen::MatrixXd model = random_points(3, 100, 81), other = random_points(3, 100, 82);
  const Eigen::MatrixXd test = random_points(3, 20, 83);
  const Ref3 ref(model), ref_other(other);
  Icp<double, 3> icp;
  IcpWorkspace<double, 3> ws;
  std::vector<Neighbor<double>> mine, theirs, moved;
  icp.first_matches(ref, test, nullptr, ws, mine);
  icp.first_matches(ref_other, test, nullptr, ws, theirs);
  RigidTransform<double, 3> shift = RigidTransform<double, 3>::identity(3);
  shift.t << 0.3, 0, 0;
  icp.first_matches(ref, test, &shift, ws, moved);
  CHECK(argument_of([&] { icp.align(ref, test, nullptr, ws, theirs); }) == "first_matches");
  CHECK(argument_of([&] { icp.align(ref, test, nullptr, ws, moved); }) == "first_matches");
  CHECK(argument_of([&] { icp.align(ref, test, &shift, ws, mine); }) == "first_matches");
  CHECK(argument_of([&] { icp.align(ref, test.leftCols(19), nullptr, ws, mine); }) == "first_matches");
  std::vector<Neighbor<double>> bad = mine;
  bad[7].index = 100;
  try {
    icp.align(ref, test, nullptr, ws, bad);
    FAIL("an out-of-range match was accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "first_matches");
    CHECK(std::string(e.what()).find("entry 7") != std::string::npos);
  }
  bad = mine;
  bad[3].squared_distance *= 1.01;
  CHECK(argument_of([&] { icp.align(ref, test, nullptr, ws, bad); }) == "first_matches");
  bad = mine;
  bad[5].squared_distance = std::numeric_limits<double>::infinity();  // its tolerance was infinite too
  CHECK(argument_of([&] { icp.align(ref, test, nullptr, ws, bad); }) == "first_matches");
  // The same matches are accepted, and centroid alignment (which makes the
  // first matching depend on the whole test) refuses them.
  CHECK(icp.align(ref, test, nullptr, ws, mine).error == icp.align(ref, test, nullptr, ws).error);
  icp.centroid_alignment = true;
  CHECK(argument_of([&] { icp.first_matches(ref, test, nullptr, ws, mine); }) == "centroid_alignment");
  CHECK(argument_of([&] { icp.align(ref, test, nullptr, ws, mine); }) == "centroid_alignment");
}

TEST_CASE("the default search scans small references, builds trees for large ones, and registers alike") {
  Icp<double, 3, Planar> icp;
  for (Index n : {100, 2000}) {  // 300 and 6000 coordinates, either side of 2048
    CAPTURE(n);
    const Eigen::MatrixXd model = random_points(3, n, 91);
    Eigen::VectorXd t;
    const Eigen::MatrixXd R = random_motion<Planar>(3, 0.15, 0.05, 92, t);
    const Eigen::MatrixXd test = R.transpose() * (model.leftCols(40).colwise() - t);
    const ReferenceCloud<double, 3> by_default(model);
    CHECK(by_default.search().uses_tree() == (n == 2000));
    const ReferenceCloud<double, 3> copy = by_default;  // copies share the search structure
    CHECK(&copy.search().points() == &by_default.search().points());
    const auto a = icp.align(by_default, test);
    const auto b = icp.align(ReferenceCloud<double, 3, KdTreeSearch<double, 3>>(model), test);
    const auto c = icp.align(ReferenceCloud<double, 3, BruteForceSearch<double, 3>>(model), test);
    CHECK(a.iterations > 1);
    for (const auto* r : {&b, &c}) {
      CHECK(r->iterations == a.iterations);
      CHECK(r->error == a.error);
      CHECK(r->T_model_test.R == a.T_model_test.R);
      CHECK(r->T_model_test.t == a.T_model_test.t);
    }
  }
}
