// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "iclap/core/types.hpp"

namespace iclap {

/// What a transform model estimates from matched pairs: the motion of the
/// block of leading coordinates it moves, x_B -> R x_B + t, and whether the
/// pairs left part of that motion undetermined.
template <typename Acc, int B>
struct BlockEstimate {
  SquareMatrix<Acc, B> R;
  Point<Acc, B> t;
  /// The cross-covariance of the pairs has lower rank than the block: the
  /// points do not span every moved axis (identical, collinear, coplanar in
  /// 3-D, fewer points than dimensions...), so at least one rotational degree
  /// of freedom is fixed only by the proper-rotation constraint or not at all.
  bool degenerate = false;
};

namespace detail {

/// Relative singular-value threshold below which H counts as rank deficient:
/// a few hundred units of the input scalar's epsilon (the data are rounded at
/// that level, the sums are accumulated in double).
template <typename Scalar>
double rank_tolerance(Index block) {
  return 64.0 * static_cast<double>(std::max<Index>(block, 8)) *
         static_cast<double>(std::numeric_limits<Scalar>::epsilon());
}

template <typename Acc, int B>
bool rank_deficient(const Point<Acc, B>& singular_values, double tolerance) {
  const Index n = singular_values.size();
  if (n == 0) return false;
  const Acc largest = singular_values(0);
  return !(largest > 0) || singular_values(n - 1) <= largest * static_cast<Acc>(tolerance);
}

/// The rotation maximising tr(R H) over SO(B): with H = U S V^T (paper,
/// Eqs. for tr(RH) <= tr(sqrt(H^T H))), R = V U^T, and the reflection guard
/// the paper's derivation lacks: if det(V U^T) = -1 (a reflection, which
/// happens for noisy or planar data), the column of V belonging to the
/// smallest singular value is negated, giving the best proper rotation
/// (Umeyama 1991). H is the cross-covariance sum_i p'_i q'_i^T of centred
/// test (p) and model (q) points.
template <typename Acc, int B>
void proper_rotation(const SquareMatrix<Acc, B>& H, double rank_tol, SquareMatrix<Acc, B>& R, bool& degenerate) {
  using Matrix = SquareMatrix<Acc, B>;
  const Index n = H.rows();
  auto decompose = [&](const auto& svd) {
    const Matrix& U = svd.matrixU();
    Matrix V = svd.matrixV();
    R.noalias() = V * U.transpose();
    if (R.determinant() < 0) {
      V.col(n - 1) *= Acc(-1);
      R.noalias() = V * U.transpose();
    }
    degenerate = rank_deficient<Acc, B>(svd.singularValues(), rank_tol);
  };
  // Jacobi for small blocks, divide and conquer for large ones; decided at
  // compile time when the size is fixed, so a 3-D registration never
  // compiles the (large) BDCSVD code.
  if constexpr (B != Eigen::Dynamic && B <= 16) {
    decompose(Eigen::JacobiSVD<Matrix>(H, Eigen::ComputeFullU | Eigen::ComputeFullV));
  } else if constexpr (B != Eigen::Dynamic) {
    decompose(Eigen::BDCSVD<Matrix>(H, Eigen::ComputeFullU | Eigen::ComputeFullV));
  } else if (n <= 16) {
    decompose(Eigen::JacobiSVD<Matrix>(H, Eigen::ComputeFullU | Eigen::ComputeFullV));
  } else {
    decompose(Eigen::BDCSVD<Matrix>(H, Eigen::ComputeFullU | Eigen::ComputeFullV));
  }
}

}  // namespace detail
}  // namespace iclap
