// SPDX-License-Identifier: MIT
// Numerical stability of the N-D ICP at the extremes: large offsets, tiny and
// huge scales, reflections, degenerate geometry, tiny clouds.

#include <array>
#include <string>
#include <type_traits>
#include <vector>

#include "../support/errors.hpp"
#include "icp_test_util.hpp"

using namespace iclap;
using namespace iclap::test;

constexpr int Dyn = Eigen::Dynamic;
#define ICLAP_EXTREME_CONFIGS                                                                            \
  Config<float, 2, 2, FullRigid>, Config<float, 3, 3, FullRigid>, Config<float, 4, 4, FullRigid>,        \
      Config<float, 8, 8, FullRigid>, Config<float, Dyn, 67, FullRigid>, Config<float, 4, 4, SpatialRigid>, \
      Config<double, 2, 2, FullRigid>, Config<double, 3, 3, FullRigid>, Config<double, 4, 4, FullRigid>, \
      Config<double, 8, 8, FullRigid>, Config<double, Dyn, 67, FullRigid>, Config<double, 4, 4, SpatialRigid>

namespace {

/// Registers T^-1(model) against model, where model = scale * unit cloud +
/// offset and T is a motion about the cloud centre (rotation, and a shift of
/// 3% of the scale). Returns the recovered rotation and the recovered local
/// translation T(o) - o divided by the scale, so that results at any offset
/// and scale are comparable with those at the origin and unit scale.
template <typename C>
std::pair<Eigen::MatrixXd, Eigen::VectorXd> recovered_motion(double offset, double scale) {
  using S = typename C::Scalar;
  const Index d = C::dim;
  const Eigen::MatrixXd unit = random_points(d, d > 10 ? 160 : 200, 101);
  Eigen::VectorXd t;
  const Eigen::MatrixXd R = random_motion<typename C::Model>(d, 0.05, 0.03, 102, t);
  const Eigen::VectorXd o = Eigen::VectorXd::Constant(d, offset);
  const Eigen::MatrixXd model = (scale * unit).colwise() + o;
  const Eigen::MatrixXd test = (R.transpose() * ((scale * unit).colwise() - scale * t)).colwise() + o;
  Icp<S, C::Dim, typename C::Model> icp;
  icp.termination.max_iterations = 100;
  const auto r = icp.align(ReferenceCloud<S, C::Dim>(model.template cast<S>()), test.template cast<S>());
  REQUIRE(r.converged);
  REQUIRE(r.T_model_test.R.allFinite());
  const Eigen::MatrixXd Rr = r.T_model_test.R.template cast<double>();
  const Eigen::VectorXd tr = r.T_model_test.t.template cast<double>();
  // T(o) - o = R o + t - o, computed as (R - I) o + t.
  const Eigen::VectorXd local = ((Rr - Eigen::MatrixXd::Identity(d, d)) * o + tr) / scale;
  CHECK(difference(Rr, R) < eps<S>(400) * (1.0 + offset / scale));
  return {Rr, local};
}

}  // namespace

TEST_CASE_TEMPLATE("a large coordinate offset recovers the same motion as at the origin", C, ICLAP_EXTREME_CONFIGS) {
  using S = typename C::Scalar;
  const double offset = std::is_same_v<S, double> ? 1e6 : 1e3;
  const auto [R0, t0] = recovered_motion<C>(0.0, 1.0);
  const auto [R1, t1] = recovered_motion<C>(offset, 1.0);
  // Inputs are rounded at eps * offset, so that is the attainable accuracy.
  const double tol = eps<S>(400) * (1.0 + offset);
  CHECK(difference(R0, R1) < tol);
  CHECK(difference(t0, t1) < tol);
}

TEST_CASE_TEMPLATE("scales from 1e-6 m to 1e3 m recover the same motion", C, ICLAP_EXTREME_CONFIGS) {
  using S = typename C::Scalar;
  const auto [R0, t0] = recovered_motion<C>(0.0, 1.0);
  for (double scale : {1e-6, 1e-3, 1e3}) {
    CAPTURE(scale);
    const auto [R1, t1] = recovered_motion<C>(0.0, scale);
    CHECK(difference(R0, R1) < eps<S>(400));
    CHECK(difference(t0, t1) < eps<S>(400));
  }
}

TEST_CASE_TEMPLATE("a cloud too small for the scalar type is refused, not registered to its initial transform", S,
                   float, double) {
  // Below sqrt(min normal) / epsilon the squared distances underflow: the
  // registration stopped at iteration 0 with E = 0, "converged", at the
  // identity (scale 1e-22 in float, 1e-170 in double).
  const double too_small = std::is_same_v<S, float> ? 1e-15 : 1e-160;
  const double fine = std::is_same_v<S, float> ? 1e-11 : 1e-130;
  using Ref = ReferenceCloud<S, 3>;  // (no comma inside doctest's macros)
  const Eigen::MatrixXd unit = random_points(3, 40, 7);
  try {
    Ref r((too_small * unit).cast<S>());
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "points");
    CHECK_MESSAGE(std::string(e.what()).find("underflow") != std::string::npos, e.what());
  }
  // So is a metric that shrinks a cloud that far.
  CHECK_THROWS_AS(Ref(unit.cast<S>(), Eigen::Vector3d::Constant(too_small)), InvalidArgument);
  const Ref ok((fine * unit).cast<S>());
  CHECK(ok.size() == 40);
  // One point (or identical points) has no scale to lose.
  using TwoPoints = Eigen::Matrix<S, 3, 2>;
  CHECK(Ref(TwoPoints::Constant(S(0.5))).size() == 2);
}

// Expected: a float cloud of distinct points whose weighted distances are
// far below sqrt(min normal) / epsilon is refused naming "points", as the
// ReferenceCloud doc and the test above promise.
// Happened: the spread is measured after the working points are cast to
// float (reference_cloud.hpp, `spread` from `work`); weighted distances of
// 1e-50 (float points 1e-30 apart, weights 1e-20, or double points 1e-46
// apart) round to 0 there, the spread reads 0 as for a single point, the
// cloud is accepted, and a test shifted by half its extent registers
// "converged" at iteration 0 with E = 0 at the identity.
TEST_CASE("a float cloud whose weighted distances round to zero is refused, not taken for one point") {
  Eigen::Matrix3Xf points = Eigen::Matrix3Xf::Zero(3, 4);
  points(0, 1) = points(1, 2) = points(2, 3) = 1e-30f;  // distinct, and normal floats
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(points, Eigen::Vector3f::Constant(1e-20f)); }) == "points");
  Eigen::Matrix3Xd tiny = Eigen::Matrix3Xd::Zero(3, 4);
  tiny(0, 1) = tiny(1, 2) = tiny(2, 3) = 1e-46;
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(tiny); }) == "points");
  // The larger metric, whose distances stay subnormal, is refused already.
  CHECK(argument_of([&] { ReferenceCloud<float, 3> r(points, Eigen::Vector3f::Constant(1e-10f)); }) == "points");
}

TEST_CASE_TEMPLATE("a cloud too large for the scalar type is refused, not registered to inf or NaN", S, float,
                   double) {
  // Beyond largest_coordinate<S>() (1.84467e+15 in float, 1.34078e+150 in
  // double) squared distances overflow; points given in double beyond
  // float's range were cast to inf.
  const double too_large = std::is_same_v<S, float> ? 1e20 : 1e151;
  const double fine = std::is_same_v<S, float> ? 1e14 : 1e140;
  using Ref = ReferenceCloud<S, 3>;
  const Eigen::MatrixXd unit = random_points(3, 40, 7);
  try {
    Ref r(too_large * unit);
    FAIL("accepted");
  } catch (const InvalidArgument& e) {
    CHECK(e.argument() == "points");
    CHECK_MESSAGE(std::string(e.what()).find("overflow") != std::string::npos, e.what());
  }
  // The farthest coordinate is named, also for a cloud of your own type.
  Eigen::MatrixXd one_far = unit;
  one_far(2, 17) = too_large;
  std::vector<std::array<double, 3>> records(40);
  for (Index j = 0; j < 40; ++j) records[static_cast<std::size_t>(j)] = {one_far(0, j), one_far(1, j), one_far(2, j)};
  for (const std::string& what : {what_of([&] { Ref r(one_far); }), what_of([&] { Ref r(records); })}) {
    CHECK_MESSAGE(what.find("points: largest weighted distance from the centroid is ") == 0, what);
    CHECK_MESSAGE(what.find(" (coordinate 2 of point 17), beyond ") != std::string::npos, what);
  }
  // So is a metric that stretches a cloud that far, and points the scalar
  // type cannot hold at all (double's largest values overflow the centring).
  CHECK_THROWS_AS(Ref(unit, Eigen::Vector3d::Constant(too_large)), InvalidArgument);
  Eigen::MatrixXd huge = unit;
  huge.row(0).setConstant(std::is_same_v<S, float> ? 1e39 : 1.7e308);
  huge(0, 3) = -huge(0, 3);
  CHECK_THROWS_AS(Ref{huge}, InvalidArgument);
  // Farther from the origin than that but small is fine: the cloud is
  // centred first (the test's coordinates are then the user's concern).
  const Ref far_ok(((std::is_same_v<S, float> ? 1e5 : 1e140) * unit.array() +
                    (std::is_same_v<S, float> ? 1e20 : 1e155)).matrix());
  CHECK(far_ok.size() == 40);
  const Ref ok(fine * unit);
  CHECK(ok.size() == 40);
  const auto r = Icp<S, 3>().align(ok, (fine * unit).cast<S>());
  CHECK(r.T_model_test.t.allFinite());
}

TEST_CASE_TEMPLATE("point sets whose SVD gives det = -1 return a proper rotation", C, ICLAP_EXTREME_CONFIGS) {
  using S = typename C::Scalar;
  const Index d = C::dim;
  // The test cloud is the mirror image of the model: the best orthogonal map
  // is a reflection, which the guard must refuse.
  const Eigen::MatrixXd model = random_points(d, d > 10 ? 160 : 200, 55);
  Eigen::MatrixXd test = model;
  test.row(0) *= -1.0;
  Icp<S, C::Dim, typename C::Model> icp;
  const auto r = icp.align(ReferenceCloud<S, C::Dim>(model.template cast<S>()), test.template cast<S>());
  const Eigen::MatrixXd R = r.T_model_test.R.template cast<double>();
  const Index b = C::Model::block_size(d);
  CHECK(R.allFinite());
  CHECK(std::abs(R.determinant() - 1.0) < eps<S>(1000));
  CHECK(difference(R.topLeftCorner(b, b).transpose() * R.topLeftCorner(b, b), Eigen::MatrixXd::Identity(b, b)) <
        eps<S>(1000));
  CHECK(std::isfinite(r.error));
}

TEST_CASE("the reflection guard picks the best proper rotation") {
  // H = diag(3, 2, -1): V U^T is a reflection; over SO(3), tr(R H) is
  // maximal (= 4) at R = I.
  const Eigen::Matrix3d H = Eigen::Vector3d(3, 2, -1).asDiagonal();
  Eigen::Matrix3d R;
  bool degenerate = true;
  detail::proper_rotation<double, 3>(H, 1e-12, R, degenerate);
  CHECK(difference(R, Eigen::Matrix3d::Identity()) < 1e-14);
  CHECK(!degenerate);
  // A rotated version of the same problem.
  Rng rng(4);
  const Eigen::Matrix3d Q = random_rotation(3, 0.7, rng);
  detail::proper_rotation<double, 3>((H * Q.transpose()).eval(), 1e-12, R, degenerate);
  // maximise tr(R H Q^T) -> R = Q.
  CHECK(difference(R, Q) < 1e-12);
  CHECK(R.determinant() == doctest::Approx(1.0));
}

TEST_CASE("a reflection with equal smallest singular values leaves the rotation undetermined: flagged") {
  // H = diag(3, 1, -1) has full rank, but over SO(3) tr(R H) = 3 for every
  // turn about x: the pairs (a mirror image) do not determine the rotation.
  const Eigen::Matrix3d H = Eigen::Vector3d(3, 1, -1).asDiagonal();
  Eigen::Matrix3d R;
  bool degenerate = false;
  detail::proper_rotation<double, 3>(H, 1e-12, R, degenerate);
  CHECK(degenerate);
  CHECK((R * H).trace() == doctest::Approx(3.0));
  // Through the estimator of the spatial block, at any size.
  const auto e = SpatialRigid::estimate<double, 3>(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), H, 1e-12);
  CHECK(e.degenerate);
  Eigen::Matrix4d H4 = Eigen::Vector4d(5, 3, 1, -1).asDiagonal();
  Eigen::Matrix4d R4;
  degenerate = false;
  detail::proper_rotation<double, 4>(H4, 1e-12, R4, degenerate);
  CHECK(degenerate);
  // Distinct smallest singular values: the flipped optimum is unique.
  detail::proper_rotation<double, 3>(Eigen::Matrix3d(Eigen::Vector3d(3, 2, -1).asDiagonal()), 1e-12, R, degenerate);
  CHECK_FALSE(degenerate);
  // The planar model: H = diag(1, -1) is pure reflection, tr(R H) = 0 for
  // every angle; it returned the identity with the flag down.
  const auto p = Planar::estimate<double, 2>(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                             Eigen::Matrix2d(Eigen::Vector2d(1, -1).asDiagonal()), 1e-12);
  CHECK(p.degenerate);
  const auto q = Planar::estimate<double, 2>(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                             Eigen::Matrix2d(Eigen::Vector2d(1, -0.5).asDiagonal()), 1e-12);
  CHECK_FALSE(q.degenerate);
}

TEST_CASE("the 3x3 closed form agrees with the SVD, or declines") {
  // The reference: the SVD route of proper_rotation for a 3x3 block.
  auto by_svd = [](const Eigen::Matrix3d& H) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d V = svd.matrixV();
    Eigen::Matrix3d R = V * svd.matrixU().transpose();
    if (R.determinant() < 0) {
      V.col(2) *= -1.0;
      R = V * svd.matrixU().transpose();
    }
    return R;
  };
  Rng rng(77);
  int accepted = 0, total = 0;
  // Condition numbers from 2 to 1e8, both signs of det H, scales 1e-12..1e12
  // (condition 1 with det H < 0 is a mirror, declined below).
  for (double condition : {2.0, 10.0, 1e3, 1e5, 1e8}) {
    for (double scale : {1e-12, 1.0, 1e12}) {
      for (int k = 0; k < 40; ++k) {
        CAPTURE(condition);
        CAPTURE(scale);
        const Eigen::Matrix3d U = random_rotation(3, 3.0, rng), V = random_rotation(3, 3.0, rng);
        Eigen::Vector3d s(1.0, std::pow(condition, -0.5 - 0.1 * (rng.uniform() - 0.5)), 1.0 / condition);
        if (k % 2 == 1) s(2) = -s(2);  // det H < 0: the reflection guard's case
        const Eigen::Matrix3d H = scale * U * s.asDiagonal() * V.transpose();
        Eigen::Matrix3d R;
        bool degenerate = true;
        ++total;
        if (!detail::polar_rotation3<double>(H, 1e-12, R, degenerate)) {
          // Declining is allowed only where the closed form is inaccurate.
          CHECK(condition >= 1e3);
          continue;
        }
        ++accepted;
        CHECK(std::abs(R.determinant() - 1.0) < 1e-14);
        CHECK(difference(R.transpose() * R, Eigen::Matrix3d::Identity()) < 1e-14);
        CHECK(difference(R, by_svd(H)) < 1e-15 * condition * 100);
        CHECK(degenerate == false);
      }
    }
  }
  // Well-conditioned cases (two of the five conditions) all take the fast path.
  CHECK(accepted >= total * 2 / 5);
  // Rank-deficient and non-finite H: declined, the SVD decides.
  Eigen::Matrix3d R;
  bool degenerate = false;
  CHECK_FALSE(detail::polar_rotation3<double>(Eigen::Vector3d(1, 1, 0).asDiagonal(), 1e-12, R, degenerate));
  CHECK_FALSE(detail::polar_rotation3<double>(Eigen::Matrix3d::Zero(), 1e-12, R, degenerate));
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(detail::polar_rotation3<double>(bad, 1e-12, R, degenerate));
  // A mirror (all singular values equal, det < 0): the optimum is not unique.
  CHECK_FALSE(detail::polar_rotation3<double>(Eigen::Vector3d(1, 1, -1).asDiagonal(), 1e-12, R, degenerate));
}

TEST_CASE("the 3x3 closed form flags a reflection tie exactly as the SVD of any size does") {
  // Reflected H with its two smallest singular values apart by `gap`, under
  // float's rank tolerance (6.1e-5): the closed form kept gaps above 1e-9
  // unflagged while the SVD (Dim = Dynamic) flagged them.
  const double tol = detail::rank_tolerance<float>(3);
  Rng rng(79);
  for (double gap : {1e-1, 1e-3, 2 * tol, tol * 1.01, tol * 0.99, 1e-5, 1e-7, 1e-10}) {
    for (int k = 0; k < 5; ++k) {
      CAPTURE(gap);
      CAPTURE(k);
      const Eigen::Matrix3d U = random_rotation(3, 3.0, rng), V = random_rotation(3, 3.0, rng);
      const Eigen::Matrix3d H = U * Eigen::Vector3d(1.0, 0.01 + gap, -0.01).asDiagonal() * V.transpose();
      const RotationRoutes r = rotation_routes(H, tol);
      CHECK(r.degenerate3 == r.degenerate_dynamic);
      CHECK(r.degenerate3 == !(gap > tol));
      CHECK(difference(r.R3, r.Rd) < 1e-6 / gap);
    }
  }
}

TEST_CASE("the planar model's closed-form singular values flag rank deficiency like the SVD") {
  Rng rng(78);
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  for (int k = 0; k < 400; ++k) {
    CAPTURE(k);
    Eigen::Matrix2d H;
    for (Index i = 0; i < 4; ++i) H.data()[i] = rng.uniform() - 0.5;
    if (k % 4 == 1) H.col(1) = H.col(0) * (rng.uniform() - 0.5);  // rank 1 (collinear points)
    if (k % 4 == 2) H.col(1) = H.col(0) * 1e-15 + H.col(1) * 1e-17;  // numerically rank 1
    if (k % 4 == 3) H *= std::pow(10.0, 24 * rng.uniform() - 12);    // any scale
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(H);
    for (double tol : {1e-13, 1e-4}) {
      const bool expected = detail::rank_deficient<double, 2>(svd.singularValues(), tol);
      const auto e = Planar::estimate<double, 2>(zero, zero, H, tol);
      const double s_min = svd.singularValues()(1), s_max = svd.singularValues()(0);
      // Away from the threshold itself, the two must agree.
      if (std::abs(s_min - tol * s_max) > 1e-3 * tol * s_max) CHECK(e.degenerate == expected);
      CHECK(std::abs(e.R.determinant() - 1.0) < 1e-14);
    }
  }
  const auto zero_h = Planar::estimate<double, 2>(zero, zero, Eigen::Matrix2d::Zero(), 1e-13);
  CHECK(zero_h.degenerate);
  CHECK(zero_h.R.isIdentity(0));
}

TEST_CASE("the planar model's rotation maximises tr(R H), as the angle atan2(b, a) gives it") {
  Rng rng(79);
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  auto by_angle = [](const Eigen::Matrix2d& H) {
    const double t = std::atan2(H(0, 1) - H(1, 0), H(0, 0) + H(1, 1));
    Eigen::Matrix2d R;
    R << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    return R;
  };
  for (int k = 0; k < 400; ++k) {
    CAPTURE(k);
    Eigen::Matrix2d H;
    for (Index i = 0; i < 4; ++i) H.data()[i] = rng.uniform() - 0.5;
    H *= std::pow(10.0, 600 * rng.uniform() - 300);  // any scale double holds
    const auto e = Planar::estimate<double, 2>(zero, zero, H, 1e-13);
    const Eigen::Matrix2d R = by_angle(H);
    CHECK((e.R - R).cwiseAbs().maxCoeff() < 4e-16);
    CHECK((e.R * H).trace() >= (R * H).trace() - 1e-15 * H.cwiseAbs().maxCoeff());  // norm() would underflow
  }
  // Overflowing norms fall back to the angle: still a rotation.
  Eigen::Matrix2d huge;
  huge << 1e308, 0.9e308, -1.5e308, 1.2e308;
  const auto h = Planar::estimate<double, 2>(zero, zero, huge, 1e-13);
  CHECK((h.R - by_angle(huge)).cwiseAbs().maxCoeff() < 4e-16);
  CHECK(std::abs(h.R.determinant() - 1.0) < 1e-14);
}

TEST_CASE_TEMPLATE("degenerate geometry: finite output, no NaN, flag set", S, float, double) {
  Eigen::MatrixXd identical = Eigen::MatrixXd::Constant(3, 10, 0.25);
  Eigen::MatrixXd collinear(3, 10), coplanar(3, 40);
  for (Index j = 0; j < 10; ++j) collinear.col(j) = Eigen::Vector3d(0.1, 0.2, 0.3) * static_cast<double>(j);
  const Eigen::MatrixXd plane = random_points(2, 40, 8);
  coplanar.topRows(2) = plane;
  coplanar.row(2).setConstant(0.5);
  for (const Eigen::MatrixXd* cloud : {&identical, &collinear, &coplanar}) {
    const Eigen::MatrixXd shifted = cloud->colwise() + Eigen::Vector3d(0.01, -0.02, 0.005);
    const ReferenceCloud<S, 3> ref(cloud->template cast<S>());
    auto check = [&](const auto& r, bool expect_degenerate) {
      CHECK(r.T_model_test.R.allFinite());
      CHECK(r.T_model_test.t.allFinite());
      CHECK(std::isfinite(r.error));
      CHECK(std::isfinite(r.rmse));
      CHECK(r.degenerate == expect_degenerate);
      CHECK(std::abs(r.T_model_test.R.template cast<double>().determinant() - 1.0) < eps<S>(1000));
    };
    check(Icp<S, 3, FullRigid>().align(ref, shifted.template cast<S>()), true);
    check(Icp<S, 3, SpatialRigid>().align(ref, shifted.template cast<S>()), true);
    // A translation is always determined: not degenerate, and exact here.
    const auto tr = Icp<S, 3, Translation>().align(ref, shifted.template cast<S>());
    check(tr, false);
    CHECK(difference(tr.T_model_test.t, Eigen::Vector3d(-0.01, 0.02, -0.005)) < eps<S>(100));
  }
  // Collinear in the plane is degenerate for the planar model too.
  Eigen::MatrixXd line2(2, 6);
  for (Index j = 0; j < 6; ++j) line2.col(j) = Eigen::Vector2d(1.0, 2.0) * static_cast<double>(j);
  const auto pr = Icp<S, 2, Planar>().align(ReferenceCloud<S, 2>(line2.template cast<S>()), line2.template cast<S>());
  CHECK(pr.degenerate);
  CHECK(pr.T_model_test.R.allFinite());
  // 4-D iCLAP points that all carry the same label: degenerate in 4-D.
  Eigen::MatrixXd labeled(4, 30);
  labeled.topRows(3) = random_points(3, 30, 9);
  labeled.row(3).setConstant(7.0);
  const auto lr = Icp<S, 4, FullRigid>().align(ReferenceCloud<S, 4>(labeled.template cast<S>()), labeled.template cast<S>());
  CHECK(lr.degenerate);
}

TEST_CASE_TEMPLATE("clouds of one and two points, and a model smaller than the test", S, float, double) {
  Eigen::MatrixXd one(3, 1);
  one << 1.0, 2.0, 3.0;
  const Eigen::MatrixXd one_test = one.colwise() - Eigen::Vector3d(0.1, 0.0, -0.2);
  const auto r1 = Icp<S, 3, FullRigid>().align(ReferenceCloud<S, 3>(one.template cast<S>()), one_test.template cast<S>());
  CHECK(r1.converged);
  CHECK(r1.degenerate);
  CHECK(r1.pairs == 1);
  CHECK(r1.error < eps<S>(100));
  CHECK(difference(r1.T_model_test * one_test.template cast<S>(), one) < eps<S>(100) * 4);

  Eigen::MatrixXd two(3, 2);
  two << 0.0, 1.0, 0.0, 0.0, 0.0, 0.0;
  const auto r2 = Icp<S, 3, FullRigid>().align(ReferenceCloud<S, 3>(two.template cast<S>()), (two.colwise() + Eigen::Vector3d(0.1, 0.1, 0)).template cast<S>());
  CHECK(r2.degenerate);
  CHECK(r2.T_model_test.R.allFinite());
  CHECK(r2.error < eps<S>(100));

  // 3 model points, 50 test points: many test points share a partner.
  const Eigen::MatrixXd small_model = random_points(3, 3, 12);
  const Eigen::MatrixXd big_test = random_points(3, 50, 13);
  const auto r3 = Icp<S, 3, FullRigid>().align(ReferenceCloud<S, 3>(small_model.template cast<S>()), big_test.template cast<S>());
  CHECK(r3.pairs == 50);
  CHECK(r3.T_model_test.R.allFinite());
  CHECK(std::isfinite(r3.error));
  CHECK(std::abs(r3.T_model_test.R.template cast<double>().determinant() - 1.0) < eps<S>(1000));
}
