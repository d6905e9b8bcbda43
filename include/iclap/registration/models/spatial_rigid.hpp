// SPDX-License-Identifier: MIT
#pragma once

#include "iclap/core/error.hpp"
#include "iclap/registration/models/procrustes.hpp"

namespace iclap {

/// Transform model: rotation and translation of the three position
/// coordinates (x, y, z) only. Any further coordinates (a word label, a
/// descriptor) take part in matching and in the error but are never moved:
/// a label is not a place. Needs Dim >= 3.
struct SpatialRigid {
  static constexpr const char* name = "spatial";
  template <int Dim>
  static constexpr int block = 3;
  static Index block_size(Index /*dim*/) noexcept { return 3; }
  static constexpr bool uses_covariance = true;
  static void check_dimension(Index dim) {
    if (dim < 3)
      throw InvalidArgument("test", "the spatial transform model needs at least 3 coordinates (x, y, z), got " +
                                        std::to_string(dim));
  }
  template <typename Acc, int B>
  static BlockEstimate<Acc, B> estimate(const Point<Acc, B>& cp, const Point<Acc, B>& cq,
                                        const SquareMatrix<Acc, B>& H, double rank_tol) {
    return detail::rigid_estimate<Acc, B>(cp, cq, H, rank_tol);
  }
};

}  // namespace iclap
