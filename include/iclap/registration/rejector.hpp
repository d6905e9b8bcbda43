// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "iclap/core/error.hpp"
#include "iclap/registration/correspondence.hpp"

namespace iclap {

/// Correspondence rejection policy of `Icp`: a maximum correspondence
/// distance, then trimming (Chetverikov et al.'s trimmed ICP: keep the
/// closest fraction of the remaining pairs). The defaults reject nothing,
/// which is the paper's plain ICP.
///
/// A custom rejector provides `void validate() const` and
/// `Index select(Correspondence<Scalar>* pairs, Index n) const`, which moves
/// the kept pairs to the front and returns how many it kept. It must be
/// deterministic (same input, same output).
template <typename Scalar>
struct DistanceRejector {
  /// Pairs farther apart than this (weighted distance, the cloud's units)
  /// are dropped. Infinity: none.
  Scalar max_distance = std::numeric_limits<Scalar>::infinity();
  /// Fraction of the remaining pairs kept, the closest ones, in (0, 1]; the
  /// count is rounded up, so at least one pair survives. 1: no trimming.
  Scalar trim_fraction = 1;

  void validate() const {
    if (!(max_distance > 0)) throw InvalidArgument("rejection.max_distance", "must be > 0 (got " + format_exact(max_distance) + ")");
    if (!(trim_fraction > 0 && trim_fraction <= 1))
      throw InvalidArgument("rejection.trim_fraction", "must be in (0, 1] (got " + format_exact(trim_fraction) + ")");
  }

  /// How many of `n` pairs (n >= 1) the trimming keeps: ceil(trim_fraction n),
  /// at least 1, where a product within the scalar's rounding of an integer
  /// counts as that integer.
  Index trimmed_count(Index n) const {
    if (!(trim_fraction < 1)) return n;
    // The stored fraction is the decimal the user wrote, rounded to Scalar:
    // 0.3f is 0.30000001, so 0.3f * 10 = 3.0000001 would keep 4 of 10 pairs
    // where the double 0.3 keeps 3. The product is exact in double (24 or 53
    // mantissa bits times n < 2^29); shrinking it by two of the scalar's
    // epsilons (at least 1e-12, which also absorbs double products such as
    // 0.7 * 10 = 7.0000000000000009) takes off that rounding and nothing a
    // fraction of this precision can mean.
    constexpr double guard = std::max(1e-12, 2.0 * static_cast<double>(std::numeric_limits<Scalar>::epsilon()));
    const double want = std::ceil(static_cast<double>(trim_fraction) * static_cast<double>(n) * (1.0 - guard));
    return std::clamp<Index>(static_cast<Index>(want), 1, n);
  }

  /// O(n) (distance) plus O(n) expected (nth_element) when trimming. Ties at
  /// the trimming boundary are broken by test index, so the kept set is
  /// unique.
  Index select(Correspondence<Scalar>* pairs, Index n) const {
    Index kept = n;
    if (max_distance < std::numeric_limits<Scalar>::infinity()) {
      const Scalar limit = max_distance * max_distance;
      kept = static_cast<Index>(std::partition(pairs, pairs + n, [limit](const auto& c) {
                                   return c.squared_distance <= limit;
                                 }) -
                                pairs);
    }
    if (trim_fraction < 1 && kept > 0) {
      const Index keep = trimmed_count(kept);
      if (keep < kept) {
        std::nth_element(pairs, pairs + keep - 1, pairs + kept, [](const auto& a, const auto& b) {
          return a.squared_distance < b.squared_distance ||
                 (a.squared_distance == b.squared_distance && a.test < b.test);
        });
        kept = keep;
      }
    }
    return kept;
  }
};

}  // namespace iclap
