// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "iclap/core/check.hpp"
#include "iclap/core/rotation.hpp"
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

  /// The identity of dimension `dim` (which must equal `Dim` when it is
  /// fixed; InvalidArgument naming "dim" when it is negative).
  static RigidTransform identity(Index dim = (Dim > 0 ? Dim : 0)) {
    if (Dim > 0) check_dimension(dim, Dim, "dim");
    if (dim < 0) throw InvalidArgument("dim", "must be >= 0, got " + std::to_string(dim));
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

  /// The largest entry of |Q^T Q - I| that `check_rotation` lets pass: a
  /// 3-D rotation rounded to four decimals is off by at most 2e-4 and
  /// passes; a rotation scaled by 1.001 is off by 0.002 and does not.
  static constexpr double rotation_tolerance = 1e-3;

  /// Throws InvalidArgument naming `argument`.R unless R is a rotation:
  /// orthogonal with det +1, or W^-1 Q W with such a Q and W =
  /// diag(`weights`) (the form of a result for a ReferenceCloud with those
  /// per-axis weights, see above), orthogonal meaning within
  /// `rotation_tolerance`. For a guess: ICP composes its motion with it, so
  /// a scaled, sheared or reflected guess gives a result that is not a
  /// rotation either. Call after `validate`. O(d^2 + m^3), m the number of
  /// coordinates R moves (rows or columns that differ from the identity's).
  template <typename WeightsDerived>
  void check_rotation(const Eigen::MatrixBase<WeightsDerived>& weights, const std::string& argument) const {
    const Index d = dim();
    check_dimension(weights.size(), d, "weights");
    std::vector<Index> moved;
    for (Index k = 0; k < d; ++k) {
      bool unit = true;
      for (Index i = 0; i < d && unit; ++i) {
        const Scalar e = i == k ? Scalar(1) : Scalar(0);
        unit = R(i, k) == e && R(k, i) == e;
      }
      if (!unit) moved.push_back(k);
    }
    if (moved.empty()) return;
    const auto m = static_cast<Index>(moved.size());
    // R is the identity outside the moved rows and columns: R's determinant
    // and orthogonality are those of its moved block.
    Eigen::MatrixXd Q(m, m), Qw(m, m);
    for (Index a = 0; a < m; ++a)
      for (Index b = 0; b < m; ++b) {
        const auto i = moved[static_cast<std::size_t>(a)], j = moved[static_cast<std::size_t>(b)];
        Q(a, b) = static_cast<double>(R(i, j));
        Qw(a, b) = static_cast<double>(weights(i)) * Q(a, b) / static_cast<double>(weights(j));
      }
    // Qw = W Q W^-1 is similar to Q: the same determinant.
    const std::string why = rotation_fault(std::min(orthogonality_deviation(Q), orthogonality_deviation(Qw)),
                                           Q.determinant(), rotation_tolerance);
    if (why.empty()) return;
    throw InvalidArgument(argument + ".R",
                          why + ". ICP composes its motion with this transform, so its result would not be a "
                                "rotation either; pass a rotation (see RigidTransform)");
  }

  /// The same transform in another scalar type.
  template <typename Other>
  RigidTransform<Other, Dim> cast() const {
    return {R.template cast<Other>(), t.template cast<Other>()};
  }
};

}  // namespace iclap
