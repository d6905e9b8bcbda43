// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

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

/// The largest coordinate magnitude a registration in `Scalar` takes:
/// 1e-4 of the square root of the type's largest value (1.84467e+15 for
/// float, 1.34078e+150 for double): the squared distance of two points in
/// range is at most 4e-8 of that value, so sums of up to 2.5e7 of them stay
/// finite. Beyond it a coordinate is a unit error or corruption (1e300 m).
template <typename Scalar>
double largest_coordinate() {
  static_assert(std::numeric_limits<Scalar>::max() <= std::numeric_limits<double>::max(),
                "iclap: largest_coordinate is for float and double");
  return 1e-4 * std::sqrt(static_cast<double>(std::numeric_limits<Scalar>::max()));
}

/// The smallest spread (largest coordinate difference) a point set may have
/// in `Scalar` when it has any: sqrt(min normal) / epsilon (9.1e-13 for
/// float, 6.7e-139 for double). Below it squared distances underflow to
/// subnormals or zero, and distinct points look identical.
template <typename Scalar>
double smallest_spread() {
  return std::sqrt(static_cast<double>(std::numeric_limits<Scalar>::min())) /
         static_cast<double>(std::numeric_limits<Scalar>::epsilon());
}

/// The first coefficient of `m`, in column-major order, whose magnitude
/// times its row's weight (`row_weights`: one per row; null: every weight
/// 1) is beyond largest_coordinate<Scalar>() (NaN included), as {row,
/// column}; {-1, -1} when all are in range. For callers that name the
/// offending point their own way (a file's line); check_coordinate_range
/// throws for the rest.
template <typename Scalar, typename Derived>
std::pair<Eigen::Index, Eigen::Index> find_beyond_range(const Eigen::DenseBase<Derived>& m,
                                                        const double* row_weights = nullptr) {
  const double limit = largest_coordinate<Scalar>();
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      const double w = row_weights ? row_weights[r] : 1.0;
      if (!(std::abs(w * static_cast<double>(m(r, c))) <= limit)) return {r, c};
    }
  return {-1, -1};
}

/// Throws InvalidArgument naming `argument`, the value, its row and its
/// column when a coefficient of `m` is beyond largest_coordinate<Scalar>()
/// (NaN included): its squared distances would overflow.
template <typename Scalar, typename Derived>
void check_coordinate_range(const Eigen::DenseBase<Derived>& m, const std::string& argument) {
  const auto [r, c] = find_beyond_range<Scalar>(m);
  if (r < 0) return;
  throw InvalidArgument(argument, "value " + format_value(static_cast<double>(m(r, c))) + " at row " +
                                      std::to_string(r) + ", column " + std::to_string(c) + " is beyond the " +
                                      (std::is_same_v<Scalar, float> ? "float" : "double") +
                                      " range of distances (|v| <= " + format_value(largest_coordinate<Scalar>()) +
                                      "): squared distances would overflow; rescale");
}

/// Throws InvalidArgument naming `argument` unless `v` is finite.
inline void check_finite(double v, const std::string& argument) {
  if (!std::isfinite(v)) throw InvalidArgument(argument, "must be finite, got " + format_value(v));
}

/// Throws InvalidArgument naming `argument` unless `v` is finite and > 0.
inline void check_positive(double v, const std::string& argument) {
  if (!(v > 0) || !std::isfinite(v)) throw InvalidArgument(argument, "must be finite and positive, got " + format_value(v));
}

/// Throws InvalidArgument naming `argument` unless `v` is finite and >= 0.
inline void check_non_negative(double v, const std::string& argument) {
  if (!(v >= 0) || !std::isfinite(v)) throw InvalidArgument(argument, "must be finite and >= 0, got " + format_value(v));
}

/// Throws DimensionMismatch naming `argument` when `actual != expected`.
inline void check_dimension(Eigen::Index actual, Eigen::Index expected, const std::string& argument) {
  if (actual != expected) throw DimensionMismatch(argument, expected, actual);
}

namespace detail {

/// `m` (any Eigen type of Target's scalar: a MatrixXd, a block, a map) as a
/// `Target` matrix. When Target has a fixed row count, m's rows are checked
/// first, DimensionMismatch naming `argument`: Eigen's conversion does not
/// check them in a release build (4 rows were cut to 3, 2 rows read as 3).
template <typename Target, typename Derived>
Target checked_rows(const Eigen::MatrixBase<Derived>& m, const std::string& argument) {
  if constexpr (Target::RowsAtCompileTime != Eigen::Dynamic)
    check_dimension(m.rows(), Target::RowsAtCompileTime, argument);
  return Target(m);
}

}  // namespace detail

}  // namespace iclap
