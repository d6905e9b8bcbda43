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
  /// cross-covariance H: R = V U^T (guarded), t = cq - R cp (paper, Sec. III).
  template <typename Acc, int B>
  static BlockEstimate<Acc, B> estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq,
                                        const SquareMatrix<Acc, B>& H, double rank_tol) {
    return detail::rigid_estimate<Acc, B>(cp, cq, H, rank_tol);
  }
};

}  // namespace iclap
