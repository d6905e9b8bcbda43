// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"

namespace iclap {

/// How a classifier's distances to the N known objects are made comparable
/// with another classifier's before fusion.
enum class Normalization {
  /// d / ||d||_2 over the objects: the paper's choice (Sections III and IV,
  /// "normalized by L2 norm"). Non-negative, scale-free.
  L2,
  /// (d - min) / (max - min): the best object gets 0, the worst 1.
  MinMax,
  /// (d - mean) / standard deviation (population). Signed, so it suits
  /// weighted sums but not product fusion.
  ZScore,
};

inline const char* to_string(Normalization n) noexcept {
  switch (n) {
    case Normalization::L2: return "l2";
    case Normalization::MinMax: return "minmax";
    case Normalization::ZScore: return "zscore";
  }
  return "unknown";
}

/// Parses "l2", "minmax" or "zscore"; throws InvalidArgument naming
/// "normalization" otherwise.
inline Normalization parse_normalization(const std::string& name) {
  if (name == "l2") return Normalization::L2;
  if (name == "minmax") return Normalization::MinMax;
  if (name == "zscore") return Normalization::ZScore;
  throw InvalidArgument("normalization", quote_text(name, 60) + " is not one of l2|minmax|zscore");
}

/// Normalises `d` (one distance per object) in place. Distances must be
/// finite and, for L2 and MinMax, non-negative (NonFiniteValue /
/// InvalidArgument naming `argument`: a string, or a callable returning one,
/// called only to name an error). Degenerate inputs are defined, never NaN:
/// all zeros (L2) or all equal (MinMax, ZScore) give all zeros, a tie of
/// every object. O(N).
template <typename Name = const char*>
void normalize(Eigen::Ref<Eigen::VectorXd> d, Normalization kind, const Name& argument = "distances") {
  if (!d.allFinite()) check_finite(d, argument_name(argument));
  if (d.size() == 0) return;
  if (kind != Normalization::ZScore && d.minCoeff() < 0)
    throw InvalidArgument(argument_name(argument), "must be non-negative for " + std::string(to_string(kind)) +
                                                       " normalisation (got " + format_value(d.minCoeff()) + ")");
  switch (kind) {
    case Normalization::L2: {
      // Scale first so that huge distances cannot overflow the squares.
      const double m = d.maxCoeff();
      if (m > 0) {
        d /= m;
        d /= d.norm();
      }
      break;
    }
    case Normalization::MinMax: {
      const double lo = d.minCoeff(), hi = d.maxCoeff();
      if (hi > lo) d = (d.array() - lo) / (hi - lo);
      else d.setZero();
      break;
    }
    case Normalization::ZScore: {
      // Equal distances are a tie whatever rounding the mean makes of them
      // (0.1 three times has a mean 1 ulp off and a tiny non-zero spread).
      const double lo = d.minCoeff(), hi = d.maxCoeff();
      if (!(hi > lo)) {
        d.setZero();
        break;
      }
      // The z-score does not change with a shift or a scale, so it is
      // computed on d - min: distances a few ulps apart kept their offset
      // in the mean, whose rounding then cancelled their spread ((1, 1 +
      // 2^-52, 1) gave (0, 1.73, 0), mean 0.58). Distances of magnitude
      // beyond 1e150 (either sign), whose sum or squared deviations would
      // overflow, are scaled to magnitude 1 first, and distances less than
      // 1e-150 apart, whose squared deviations would underflow (1e-150 and
      // 1e-150 (1 + 1e-12) gave 0 and 0), are mapped onto [0, 1] by
      // (d - min) / (max - min).
      const double m = std::max(std::abs(lo), std::abs(hi));
      if (m > 1e150) d /= m;
      if (m <= 1e150 && hi - lo < 1e-150) d = (d.array() - lo) / (hi - lo);
      else d.array() -= d.minCoeff();
      const double mean = d.mean();
      const double sd = std::sqrt((d.array() - mean).square().mean());
      if (sd > 0) d = (d.array() - mean) / sd;
      else d.setZero();
      break;
    }
  }
}

}  // namespace iclap
