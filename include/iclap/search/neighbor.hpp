// SPDX-License-Identifier: MIT
#pragma once

#include <limits>

#include "iclap/core/types.hpp"

namespace iclap {

/// A nearest-neighbour answer: the index of the closest point of the searched
/// cloud and its squared (Euclidean) distance. `index < 0` means "none" (an
/// empty search structure).
template <typename Scalar>
struct Neighbor {
  Index index = -1;
  Scalar squared_distance = std::numeric_limits<Scalar>::infinity();
};

namespace detail {

/// The one squared-distance kernel every search policy uses, so that the
/// kd-tree and brute force compute bit-identical distances (and hence pick
/// identical neighbours). Summation in coordinate order.
template <int Dim, typename Scalar>
inline Scalar squared_distance(const Scalar* a, const Scalar* b, Index dim) noexcept {
  Scalar result = Scalar(0);
  const Index n = Dim > 0 ? Index(Dim) : dim;
  for (Index i = 0; i < n; ++i) {
    const Scalar d = a[i] - b[i];
    result += d * d;
  }
  return result;
}

/// Tie rule shared by all search policies: the smaller distance wins, and on
/// equal distances the smaller index.
template <typename Scalar>
inline bool closer(Scalar d, Index i, Scalar best_d, Index best_i) noexcept {
  return d < best_d || (d == best_d && i < best_i);
}

}  // namespace detail
}  // namespace iclap
