// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>

#include "iclap/registration/models/procrustes.hpp"

namespace iclap {

/// Transform model: translation of the position coordinates only (the
/// first min(Dim, 3)); nothing rotates. The least-squares translation is
/// the difference of the matched centroids, t = cq - cp. Never degenerate.
struct Translation {
  static constexpr const char* name = "translation";
  template <int Dim>
  static constexpr int block = Dim == Eigen::Dynamic ? Eigen::Dynamic : (Dim < 3 ? Dim : 3);
  static Index block_size(Index dim) noexcept { return std::min<Index>(dim, 3); }
  static constexpr bool uses_covariance = false;
  static void check_dimension(Index /*dim*/) {}
  template <typename Acc, int B>
  static BlockEstimate<Acc, B> estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq,
                                        const SquareMatrix<Acc, B>& /*H*/, double /*rank_tol*/) {
    BlockEstimate<Acc, B> e;
    e.R = SquareMatrix<Acc, B>::Identity(cp.size(), cp.size());
    e.t = cq - cp;
    e.degenerate = false;
    return e;
  }
};

}  // namespace iclap
