// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
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

/// The 3x3 case without an SVD, for a well-conditioned H (the common case of
/// every ICP iteration in 3-D and in iCLAP's spatial block). With H = U S V^T,
/// H^T H = V S^2 V^T, so R = V D U^T = V D S^-1 V^T H^T, where D flips the sign
/// belonging to the smallest singular value when det H < 0 (the same guard as
/// below). The eigenvectors of the symmetric 3x3 H^T H come in closed form,
/// which squares the condition number, so the estimate is then refined to
/// full precision and checked:
///  - Newton's polar iteration X <- (X + X^-T) / 2 removes the stretch left in
///    R (quadratic convergence);
///  - Newton steps on SO(3) drive R H to symmetric, the optimality condition of
///    tr(R H) (skew(R H) = 0): with G = R H and its symmetric part A,
///    skew(exp(-[w]) G) = 0 to first order when (tr(A) I - A) w = vee(G - G^T).
/// Returns false (and the caller takes the SVD) when H is near rank deficient
/// or either refinement fails to converge; never returns an unchecked R.
template <typename Acc>
bool polar_rotation3(const SquareMatrix<Acc, 3>& H, double rank_tol, SquareMatrix<Acc, 3>& R, bool& degenerate) {
  using M3 = SquareMatrix<Acc, 3>;
  using V3 = Point<Acc, 3>;
  constexpr Acc eps = std::numeric_limits<Acc>::epsilon();
  const Acc scale = H.cwiseAbs().maxCoeff();
  if (!(scale > 0) || !(scale < std::numeric_limits<Acc>::infinity())) return false;
  const M3 Hn = H / scale;  // |Hn| <= 1: no overflow or underflow in Hn^T Hn
  Eigen::SelfAdjointEigenSolver<M3> eig;
  eig.computeDirect(Hn.transpose() * Hn);
  const V3& lambda = eig.eigenvalues();  // ascending
  // s_min / s_max above 1e-5: the closed form's error (about eps / that
  // ratio squared) is small enough for the refinement below to converge.
  if (!(lambda(0) > lambda(2) * Acc(1e-10))) return false;
  const V3 s = lambda.cwiseSqrt();  // the singular values of Hn, ascending
  V3 inv_s = s.cwiseInverse();
  if (Hn.determinant() < 0) {
    // A reflected H whose two smallest singular values are close (within
    // twice the gap proper_rotation calls degenerate, so the closed form's
    // rounding cannot decide the flag): the SVD decides, so the rotation and
    // its degenerate flag are those of any other dimension.
    if (!(s(1) - s(0) > Acc(2) * s(2) * static_cast<Acc>(rank_tol))) return false;
    inv_s(0) = -inv_s(0);
  }
  const M3& V = eig.eigenvectors();
  M3 X = V * inv_s.asDiagonal() * V.transpose() * Hn.transpose();

  bool orthogonal = false;
  for (int k = 0; k < 4 && !orthogonal; ++k) {
    M3 inv;
    bool invertible = false;
    X.computeInverseWithCheck(inv, invertible, Acc(1e-6));
    if (!invertible) return false;
    const M3 next = Acc(0.5) * (X + inv.transpose());
    orthogonal = (next - X).cwiseAbs().maxCoeff() <= Acc(16) * eps;
    X = next;
  }
  if (!orthogonal || !(X.determinant() > 0)) return false;

  for (int k = 0; k < 4; ++k) {
    const M3 G = X * Hn;
    const V3 skew(G(2, 1) - G(1, 2), G(0, 2) - G(2, 0), G(1, 0) - G(0, 1));
    const M3 A = Acc(0.5) * (G + G.transpose());
    const M3 system = A.trace() * M3::Identity() - A;
    M3 inv;
    bool invertible = false;
    // The system is singular when the two smallest singular values of a
    // reflected H coincide: the optimum is then not unique; leave it to the SVD.
    system.computeInverseWithCheck(inv, invertible, Acc(1e-9));
    if (!invertible) return false;
    const V3 w = inv * skew;
    const Acc angle = w.norm();
    if (!(angle < Acc(1e-3))) return false;  // not near the optimum: the estimate failed
    if (angle <= Acc(8) * eps) {
      R = X;
      degenerate = !(s(0) > s(2) * static_cast<Acc>(rank_tol));
      return true;
    }
    X = Eigen::AngleAxis<Acc>(-angle, w / angle).toRotationMatrix() * X;
  }
  return false;
}

/// The rotation maximising tr(R H) over SO(B): with H = U S V^T, R = V U^T
/// (paper, Eqs. (4)-(6): tr(RH) <= tr(sqrt(H^T H)), attained there), and
/// the reflection guard the paper's derivation lacks: if det(V U^T) = -1
/// (a reflection, which happens for noisy or planar data), the column of V
/// belonging to the smallest singular value is negated, giving the best
/// proper rotation (Umeyama 1991). H is the cross-covariance
/// sum_i p'_i q'_i^T of centred test (p) and model (q) points (Eq. (3)).
template <typename Acc, int B>
void proper_rotation(const SquareMatrix<Acc, B>& H, double rank_tol, SquareMatrix<Acc, B>& R, bool& degenerate) {
  using Matrix = SquareMatrix<Acc, B>;
  const Index n = H.rows();
  auto decompose = [&](const auto& svd) {
    const Matrix& U = svd.matrixU();
    Matrix V = svd.matrixV();
    R.noalias() = V * U.transpose();
    bool flipped = false;
    if (R.determinant() < 0) {
      V.col(n - 1) *= Acc(-1);
      R.noalias() = V * U.transpose();
      flipped = true;
    }
    degenerate = rank_deficient<Acc, B>(svd.singularValues(), rank_tol);
    // Flipped, the best proper rotation is unique only when the two smallest
    // singular values differ: where they are equal, tr(R H) is the same for
    // every turn in their plane (a mirror image of pairs), so the pairs do
    // not determine the rotation, though H has full rank.
    if (flipped && n >= 2) {
      const auto& sv = svd.singularValues();
      degenerate = degenerate || !(sv(n - 2) - sv(n - 1) > sv(0) * static_cast<Acc>(rank_tol));
    }
  };
  // Jacobi for small blocks, divide and conquer for large ones; decided at
  // compile time when the size is fixed, so a 3-D registration never
  // compiles the (large) BDCSVD code.
  if constexpr (B == 3) {
    if (polar_rotation3<Acc>(H, rank_tol, R, degenerate)) return;
  }
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

/// The rigid block motion of FullRigid and SpatialRigid: R from
/// `proper_rotation`, t = cq - R cp (paper, Sec. III).
template <typename Acc, int B>
BlockEstimate<Acc, B> rigid_estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq, const SquareMatrix<Acc, B>& H,
                                     double rank_tol) {
  BlockEstimate<Acc, B> e;
  proper_rotation<Acc, B>(H, rank_tol, e.R, e.degenerate);
  e.t = cq - e.R * cp;
  return e;
}

}  // namespace detail
}  // namespace iclap
