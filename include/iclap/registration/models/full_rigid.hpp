// SPDX-License-Identifier: MIT
#pragma once

#include "iclap/registration/models/procrustes.hpp"

namespace iclap {

/// Transform model: a rigid motion of all `Dim` coordinates, R in SO(Dim),
/// t in R^Dim. This is the paper's 4-D iCLAP exactly (Section III: the 4x4
/// rotation and 4x1 translation act on (x, y, z, label)), plus the
/// reflection guard. Rotations then mix labels (and descriptors) with
/// positions; use `SpatialRigid` to keep them apart.
struct FullRigid {
  static constexpr const char* name = "full";
  /// Number of leading coordinates moved, at compile time (Dynamic if unknown).
  template <int Dim>
  static constexpr int block = Dim;
  /// Same at run time.
  static Index block_size(Index dim) noexcept { return dim; }
  static constexpr bool uses_covariance = true;
  /// Throws InvalidArgument when the model cannot act on `dim` coordinates.
  static void check_dimension(Index /*dim*/) {}

  /// Optimal block motion for centroids cp (test), cq (model) and
  /// cross-covariance H (paper, Eq. (3)): R = V U^T (guarded; Eqs. (4)-(6)),
  /// t = cq - R cp (Eqs. (1)-(2)).
  template <typename Acc, int B>
  static BlockEstimate<Acc, B> estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq,
                                        const SquareMatrix<Acc, B>& H, double rank_tol) {
    return detail::rigid_estimate<Acc, B>(cp, cq, H, rank_tol);
  }
};

}  // namespace iclap
