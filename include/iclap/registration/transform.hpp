// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include <Eigen/Core>
#include <Eigen/LU>

#include "iclap/core/check.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// x -> R x + t in `Dim` dimensions: the motion ICP estimates.
///
/// Named by frames (small_gicp's convention): a `T_model_test` maps test
/// coordinates into the model frame. `R` is a proper rotation (orthogonal,
/// det +1) for every transform model, except when a model moves coordinates
/// whose per-axis weights differ (see `ReferenceCloud`); then `R` is the
/// rotation estimated in the weighted space seen from the original axes,
/// W^-1 R_w W, and only its determinant stays +1.
template <typename Scalar, int Dim>
struct RigidTransform {
  ICLAP_CHECK_SCALAR_AND_DIM(Scalar, Dim);

  using Matrix = SquareMatrix<Scalar, Dim>;
  using Vector = Point<Scalar, Dim>;
  static constexpr int HomogeneousDim = Dim == Eigen::Dynamic ? Eigen::Dynamic : Dim + 1;
  using Homogeneous = Eigen::Matrix<Scalar, HomogeneousDim, HomogeneousDim>;

  Matrix R;
  Vector t;

  /// The identity of dimension `dim` (which must equal `Dim` when it is fixed).
  static RigidTransform identity(Index dim = (Dim > 0 ? Dim : 0)) {
    if (Dim > 0) check_dimension(dim, Dim, "dim");
    return {Matrix::Identity(dim, dim), Vector::Zero(dim)};
  }

  Index dim() const noexcept { return t.size(); }

  /// The (Dim+1) x (Dim+1) homogeneous matrix [R t; 0 1].
  Homogeneous matrix() const {
    const Index d = dim();
    Homogeneous h = Homogeneous::Identity(d + 1, d + 1);
    h.topLeftCorner(d, d) = R;
    h.topRightCorner(d, 1) = t;
    return h;
  }

  /// Applies the transform to one point or to every column of a cloud.
  template <typename Derived>
  auto operator*(const Eigen::MatrixBase<Derived>& points) const {
    return ((R * points).colwise() + t).eval();
  }

  /// Composition: (a * b)(x) = a(b(x)).
  RigidTransform operator*(const RigidTransform& other) const {
    return {R * other.R, R * other.t + t};
  }

  /// The inverse map. O(Dim^3) (a general inverse, so it is exact also for
  /// the weighted, non-orthogonal case).
  RigidTransform inverse() const {
    Matrix Ri = R.inverse();
    Vector ti = -(Ri * t);
    return {std::move(Ri), std::move(ti)};
  }

  /// Throws InvalidArgument / DimensionMismatch / NonFiniteValue naming
  /// `argument` unless R is dim x dim, t has length dim, and all is finite.
  void validate(Index expected_dim, const std::string& argument) const {
    check_dimension(R.rows(), expected_dim, argument + ".R rows");
    check_dimension(R.cols(), expected_dim, argument + ".R cols");
    check_dimension(t.size(), expected_dim, argument + ".t");
    check_finite(R, argument + ".R");
    check_finite(t, argument + ".t");
  }

  /// The same transform in another scalar type.
  template <typename Other>
  RigidTransform<Other, Dim> cast() const {
    return {R.template cast<Other>(), t.template cast<Other>()};
  }
};

}  // namespace iclap
