// SPDX-License-Identifier: MIT
#pragma once
// Shared helpers of the registration tests: random clouds, motions of the
// form each transform model can represent, and error measures.

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "iclap/core/random.hpp"
#include "iclap/registration/registration.hpp"

namespace iclap::test {

/// Points uniform in offset + scale * [-1, 1]^dim, generated in double.
inline Eigen::MatrixXd random_points(Index dim, Index n, std::uint64_t seed, double scale = 1.0,
                                     double offset = 0.0) {
  Rng rng(seed);
  Eigen::MatrixXd c(dim, n);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < dim; ++i) c(i, j) = offset + scale * rng.uniform(-1.0, 1.0);
  return c;
}

/// A rotation of SO(k) near the identity, by the Cayley transform of a random
/// skew-symmetric matrix with entries of size `magnitude`.
inline Eigen::MatrixXd random_rotation(Index k, double magnitude, Rng& rng) {
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(k, k);
  for (Index i = 0; i < k; ++i)
    for (Index j = i + 1; j < k; ++j) {
      S(i, j) = magnitude * rng.uniform(-1.0, 1.0);
      S(j, i) = -S(i, j);
    }
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(k, k);
  return (I - S).partialPivLu().solve(I + S);
}

/// A motion of dimension `dim` that `Model` can represent: rotation and
/// translation of its block only, with rotation entries ~`angle` and a
/// translation ~`shift`.
template <typename Model>
Eigen::MatrixXd random_motion(Index dim, double angle, double shift, std::uint64_t seed, Eigen::VectorXd& t) {
  Rng rng(seed);
  const Index b = Model::block_size(dim);
  Eigen::MatrixXd R = Eigen::MatrixXd::Identity(dim, dim);
  t = Eigen::VectorXd::Zero(dim);
  if constexpr (!std::is_same_v<Model, Translation>) {
    if constexpr (std::is_same_v<Model, Planar>) {
      const double a = angle * rng.uniform(0.5, 1.0);
      R.topLeftCorner(2, 2) << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    } else {
      R.topLeftCorner(b, b) = random_rotation(b, angle / std::sqrt(static_cast<double>(b)), rng);
    }
  }
  for (Index i = 0; i < b; ++i) t(i) = shift * rng.uniform(-1.0, 1.0);
  return R;
}

/// Frobenius norm of the difference of two matrices of any scalar types.
template <typename A, typename B>
double difference(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  return (a.template cast<double>() - b.template cast<double>()).norm();
}

/// The best proper rotation of a 3x3 cross-covariance H and its degenerate
/// flag, by the 3x3 route (closed form, else Jacobi SVD) and by the SVD of a
/// Dynamic block, for checks that the two routes agree.
struct RotationRoutes {
  Eigen::Matrix3d R3;
  bool degenerate3 = false;
  Eigen::MatrixXd Rd;
  bool degenerate_dynamic = false;
};

inline RotationRoutes rotation_routes(const Eigen::Matrix3d& H, double rank_tol) {
  RotationRoutes r;
  detail::proper_rotation<double, 3>(H, rank_tol, r.R3, r.degenerate3);
  r.degenerate_dynamic = !r.degenerate3;  // so that a route that never sets it fails the comparison
  detail::proper_rotation<double, Eigen::Dynamic>(Eigen::MatrixXd(H), rank_tol, r.Rd, r.degenerate_dynamic);
  return r;
}

/// k units of the scalar's epsilon.
template <typename Scalar>
constexpr double eps(double k) {
  return k * static_cast<double>(std::numeric_limits<Scalar>::epsilon());
}

/// A configuration for TEST_CASE_TEMPLATE: scalar, compile-time dimension,
/// run-time dimension (for Dynamic) and transform model.
template <typename S, int D, Index RuntimeDim, typename M>
struct Config {
  using Scalar = S;
  static constexpr int Dim = D;
  static constexpr Index dim = D > 0 ? D : RuntimeDim;
  using Model = M;
};

}  // namespace iclap::test
