// SPDX-License-Identifier: MIT
#pragma once

#include <limits>
#include <type_traits>
#include <utility>

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
/// identical neighbours). Below 8 coordinates one running sum in coordinate
/// order; from 8 on, eight independent partial sums (coordinate i goes to
/// sum i mod 8, combined pairwise), which lets the CPU overlap the additions
/// of long feature vectors (about 3x faster at 72-D).
///
/// GCC 12 analyses the unrolled path also where it is unreachable (a run-time
/// dimension below 8 with a query of known small size) and reports array
/// bounds there; the diagnostic is silenced for this function only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif
template <int Dim, typename Scalar>
inline Scalar squared_distance(const Scalar* a, const Scalar* b, Index dim) noexcept {
  const Index n = Dim > 0 ? Index(Dim) : dim;
  if (n < 8) {
    Scalar result = Scalar(0);
    for (Index i = 0; i < n; ++i) {
      const Scalar d = a[i] - b[i];
      result += d * d;
    }
    return result;
  }
  Scalar s[8] = {};
  Index i = 0;
  for (; i + 8 <= n; i += 8) {
    for (int k = 0; k < 8; ++k) {
      const Scalar d = a[i + k] - b[i + k];
      s[k] += d * d;
    }
  }
  const Index rest = n - i;  // < 8
  for (Index k = 0; k < rest && k < 8; ++k) {
    const Scalar d = a[i + k] - b[i + k];
    s[k] += d * d;
  }
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

/// True when `Search` offers the optional warm-started `nearest(query, hint)`.
template <typename Search, typename Scalar, typename = void>
struct has_hinted_nearest : std::false_type {};
template <typename Search, typename Scalar>
struct has_hinted_nearest<Search, Scalar,
                          std::void_t<decltype(std::declval<const Search&>().nearest(std::declval<const Scalar*>(),
                                                                                     Index(0)))>>
    : std::true_type {};

/// Tie rule shared by all search policies: the smaller distance wins, and on
/// equal distances the smaller index.
template <typename Scalar>
inline bool closer(Scalar d, Index i, Scalar best_d, Index best_i) noexcept {
  return d < best_d || (d == best_d && i < best_i);
}

}  // namespace detail
}  // namespace iclap
