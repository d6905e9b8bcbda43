// SPDX-License-Identifier: MIT
// Property suite of the N-D ICP over scalar x dimension x transform model.
// Compiled twice, with ICLAP_TEST_SCALAR float and double.

#include "icp_test_util.hpp"

using namespace iclap;
using namespace iclap::test;

#ifndef ICLAP_TEST_SCALAR
#error "define ICLAP_TEST_SCALAR"
#endif
using S = ICLAP_TEST_SCALAR;
constexpr int Dyn = Eigen::Dynamic;

// Every model on every dimension it supports: 2, 3, 4, 8 and Dynamic at 67.
#define ICLAP_CONFIGS                                                                                   \
  Config<S, 2, 2, FullRigid>, Config<S, 2, 2, Planar>, Config<S, 2, 2, Translation>,                    \
      Config<S, 3, 3, FullRigid>, Config<S, 3, 3, SpatialRigid>, Config<S, 3, 3, Planar>,               \
      Config<S, 3, 3, Translation>, Config<S, 4, 4, FullRigid>, Config<S, 4, 4, SpatialRigid>,          \
      Config<S, 4, 4, Planar>, Config<S, 4, 4, Translation>, Config<S, 8, 8, FullRigid>,                \
      Config<S, 8, 8, SpatialRigid>, Config<S, 8, 8, Planar>, Config<S, 8, 8, Translation>,             \
      Config<S, Dyn, 67, FullRigid>, Config<S, Dyn, 67, SpatialRigid>, Config<S, Dyn, 67, Planar>,      \
      Config<S, Dyn, 67, Translation>

namespace {

template <typename C>
struct Scene {
  using Scalar = typename C::Scalar;
  static constexpr int D = C::Dim;
  Eigen::MatrixXd model, test, R;
  Eigen::VectorXd t;
  /// test = T^-1(model), so the registration should return T_model_test = T.
  Scene(std::uint64_t seed, double angle = 0.05, double shift = 0.03) {
    const Index d = C::dim;
    model = random_points(d, d > 10 ? 160 : 200, seed);
    R = random_motion<typename C::Model>(d, angle, shift, seed + 1, t);
    test = R.transpose() * (model.colwise() - t);
  }
};

}  // namespace

TEST_CASE_TEMPLATE("a random motion inside the convergence basin is recovered", C, ICLAP_CONFIGS) {
  using Model = typename C::Model;
  for (std::uint64_t seed : {11u, 23u, 37u}) {
    const Scene<C> s(seed);
    const ReferenceCloud<S, C::Dim> ref(s.model.template cast<S>());
    Icp<S, C::Dim, Model> icp;
    icp.termination.max_iterations = 100;
    const auto r = icp.align(ref, s.test.template cast<S>());
    CAPTURE(seed);
    CHECK(r.converged);
    CHECK(r.pairs == s.test.cols());
    CHECK(!r.degenerate);
    CHECK(difference(r.T_model_test.R, s.R) < eps<S>(400));
    CHECK(difference(r.T_model_test.t, s.t) < eps<S>(400));
    CHECK(r.rmse < eps<S>(400));
    CHECK(std::abs(r.T_model_test.R.template cast<double>().determinant() - 1.0) < eps<S>(1000));
  }
}

TEST_CASE_TEMPLATE("the identity stays the identity", C, ICLAP_CONFIGS) {
  const Scene<C> s(5);
  const Cloud<S, C::Dim> model = s.model.template cast<S>();
  const ReferenceCloud<S, C::Dim> ref(model);
  Icp<S, C::Dim, typename C::Model> icp;
  // A permuted copy: every point has an exact partner.
  Cloud<S, C::Dim> test = model.rowwise().reverse();
  const auto r = icp.align(ref, test);
  CHECK(r.converged);
  CHECK(r.stop_reason == StopReason::AbsoluteTolerance);
  CHECK(r.iterations == 0);
  CHECK(r.error == S(0));
  CHECK(r.T_model_test.R == SquareMatrix<S, C::Dim>::Identity(C::dim, C::dim));
  CHECK(r.T_model_test.t == Point<S, C::Dim>::Zero(C::dim));
}

TEST_CASE_TEMPLATE("swapping fully overlapping clouds gives the inverse", C, ICLAP_CONFIGS) {
  const Scene<C> s(77);
  const Cloud<S, C::Dim> a = s.model.template cast<S>();
  const Cloud<S, C::Dim> b = s.test.template cast<S>();
  Icp<S, C::Dim, typename C::Model> icp;
  const auto ab = icp.align(ReferenceCloud<S, C::Dim>(a), b);
  const auto ba = icp.align(ReferenceCloud<S, C::Dim>(b), a);
  REQUIRE(ab.converged);
  REQUIRE(ba.converged);
  const auto product = ab.T_model_test * ba.T_model_test;
  CHECK(difference(product.R, Eigen::MatrixXd::Identity(C::dim, C::dim)) < eps<S>(800));
  CHECK(product.t.template cast<double>().norm() < eps<S>(800));
  const auto inv = ab.T_model_test.inverse();
  CHECK(difference(inv.R, ba.T_model_test.R) < eps<S>(800));
}

TEST_CASE_TEMPLATE("kd-tree and brute force give identical correspondences and results", C, ICLAP_CONFIGS) {
  // A larger motion, so that the correspondences change between iterations.
  const Scene<C> s(3, 0.2, 0.15);
  const Cloud<S, C::Dim> model = s.model.template cast<S>();
  const Cloud<S, C::Dim> test = s.test.template cast<S>();
  const ReferenceCloud<S, C::Dim, KdTreeSearch<S, C::Dim>> tree(model);
  const ReferenceCloud<S, C::Dim, BruteForceSearch<S, C::Dim>> brute(model);
  for (int iterations : {0, 1, 3, 30}) {
    Icp<S, C::Dim, typename C::Model> icp;
    icp.termination.max_iterations = iterations;
    const auto a = icp.align(tree, test);
    const auto b = icp.align(brute, test);
    CAPTURE(iterations);
    CHECK(a.iterations == b.iterations);
    CHECK(a.error == b.error);
    CHECK(a.pairs == b.pairs);
    CHECK(a.T_model_test.R == b.T_model_test.R);
    CHECK(a.T_model_test.t == b.T_model_test.t);
  }
}

TEST_CASE_TEMPLATE("the model moves only its own coordinates", C, ICLAP_CONFIGS) {
  using Model = typename C::Model;
  // Clouds that differ by a full-dimensional motion: whatever the model
  // finds, coordinates outside its block must stay untouched.
  const Index d = C::dim;
  const Index b = Model::block_size(d);
  Eigen::MatrixXd model = random_points(d, d > 10 ? 160 : 200, 9);
  Eigen::VectorXd t;
  Eigen::MatrixXd R = random_motion<FullRigid>(d, 0.1, 0.1, 10, t);
  const Eigen::MatrixXd test = R * model;
  Icp<S, C::Dim, Model> icp;
  const auto r = icp.align(ReferenceCloud<S, C::Dim>(model.template cast<S>()), test.template cast<S>());
  const auto& T = r.T_model_test;
  if (b < d) {
    CHECK(T.R.bottomRows(d - b) == Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Identity(d, d).bottomRows(d - b));
    CHECK(T.R.topRightCorner(b, d - b).isZero(0));
    CHECK(T.t.tail(d - b).isZero(0));
  }
  CHECK(T.R.allFinite());
  CHECK(T.t.allFinite());
}
