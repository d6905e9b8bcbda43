// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <type_traits>

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
  /// are dropped. Infinity: none. Its square must be a normal number (at
  /// least about 1.1e-19 for float, 1.5e-154 for double).
  Scalar max_distance = std::numeric_limits<Scalar>::infinity();
  /// Fraction of the remaining pairs kept, the closest ones, in (0, 1]; the
  /// count is rounded up, so at least one pair survives. 1: no trimming.
  Scalar trim_fraction = 1;

  void validate() const {
    if (!(max_distance > 0)) throw InvalidArgument("rejection.max_distance", "must be > 0 (got " + format_exact(max_distance) + ")");
    // Pairs are compared by squared distance: a limit whose square is 0 or
    // subnormal (float below about 1.1e-19, double 1.5e-154) kept only exact
    // matches, or compared at a fraction of the precision.
    if (!(max_distance * max_distance >= std::numeric_limits<Scalar>::min()))
      throw InvalidArgument("rejection.max_distance", "must square to a normal number, since pairs are compared by "
                                                      "squared distance (got " + format_exact(max_distance) + ")");
    if (!(trim_fraction > 0 && trim_fraction <= 1))
      throw InvalidArgument("rejection.trim_fraction", "must be in (0, 1] (got " + format_exact(trim_fraction) + ")");
  }

  /// How many of `n` pairs (n >= 1) the trimming keeps: ceil(trim_fraction n),
  /// at least 1, where trim_fraction is the decimal it was written as (0.3,
  /// not the float 0.30000001) and a product within 1e-12 of itself
  /// (relative, which absorbs the product's own rounding at any n) above an
  /// integer counts as that integer: 0.50000000000010003 of a million pairs
  /// keeps 500000.
  Index trimmed_count(Index n) const {
    if (!(trim_fraction < 1)) return n;
    // 0.3f * 10 = 3.0000001 would keep 4 of 10 pairs where the double 0.3
    // keeps 3. The decimal is taken back first (the shortest text that reads
    // back to the stored value, std::to_chars, read as a double: 0.3f gives
    // 0.3) rather than shrinking the float product by its rounding, which
    // also took off up to 2.4e-7 of the product and so kept one pair too few
    // from a few hundred thousand pairs on (0.9f of 419439 kept 377495, not
    // 377496). Shrinking the double product by 1e-12 of itself absorbs its
    // own rounding (0.7 * 10 = 7.0000000000000009) and, below 1e11 pairs,
    // nothing a fraction can mean.
    const double want = std::ceil(decimal_fraction() * static_cast<double>(n) * (1.0 - 1e-12));
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

  /// trim_fraction as the decimal it was written as: a double as it is, a
  /// float through its shortest round-trip text.
  double decimal_fraction() const {
    if constexpr (std::is_same_v<Scalar, double>) {
      return trim_fraction;
    } else {
      char buf[64];
      const auto written = std::to_chars(buf, buf + sizeof buf, trim_fraction);
      double f = static_cast<double>(trim_fraction);
      std::from_chars(buf, written.ptr, f);
      return f;
    }
  }
};

}  // namespace iclap
