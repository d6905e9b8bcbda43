// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "iclap/core/error.hpp"

namespace iclap {

/// Throws NonFiniteValue naming `argument`, the row and the column of the
/// first NaN or infinity in `m`. O(size); a no-op on finite input.
template <typename Derived>
void check_finite(const Eigen::DenseBase<Derived>& m, const std::string& argument) {
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      const auto v = m(r, c);
      if (!std::isfinite(v)) throw NonFiniteValue(argument, r, c, static_cast<double>(v));
    }
  }
}

/// Throws EmptyInput naming `argument` when `m` has no columns (no points)
/// or no rows (zero dimension).
template <typename Derived>
void check_not_empty(const Eigen::DenseBase<Derived>& m, const std::string& argument) {
  if (m.cols() == 0) throw EmptyInput(argument, "has no points");
  if (m.rows() == 0) throw EmptyInput(argument, "has dimension 0");
}

/// Throws DimensionMismatch naming `argument` when `actual != expected`.
inline void check_dimension(Eigen::Index actual, Eigen::Index expected, const std::string& argument) {
  if (actual != expected) throw DimensionMismatch(argument, expected, actual);
}

}  // namespace iclap
