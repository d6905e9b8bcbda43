// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap {

/// One tactile frame as an image: a rows x cols grid of taxel pressures in
/// the sensor's raw units (the Weiss WTS 0614-34A gives 14 x 6 taxels with
/// 12-bit values 0..4095), validated once so descriptors need not check.
///
/// Geometry convention used by every descriptor: row r grows along the pad's
/// long axis ("y", downwards in a printout), column c along the short axis
/// ("x"); pixel (r, c) is the square [c, c+1] x [r, r+1] in taxel units.
///
/// Invariants: at least one row and one column; every value finite and
/// non-negative. The grid size is a run-time value so one build serves any
/// sensor. Cheap to build from `Frame::pressures` (one copy of the matrix, or
/// none when the matrix is moved in). Immutable after construction, so const
/// access from any number of threads is safe.
class TactileImage {
 public:
  using Matrix = Eigen::MatrixXd;

  /// Takes the pressures (rows x cols, raw units). Throws EmptyInput when the
  /// grid has no rows or no columns, NonFiniteValue for NaN or infinity and
  /// InvalidArgument for a negative value; each names `argument` and, for a
  /// bad value, its row and column. O(rows * cols).
  explicit TactileImage(Matrix pressures, const std::string& argument = "pressures")
      : pressures_(std::move(pressures)) {
    if (pressures_.rows() == 0 || pressures_.cols() == 0)
      throw EmptyInput(argument, "is an empty taxel grid (" + std::to_string(pressures_.rows()) +
                                     " x " + std::to_string(pressures_.cols()) + ")");
    check_finite(pressures_, argument);
    for (Index c = 0; c < pressures_.cols(); ++c) {
      for (Index r = 0; r < pressures_.rows(); ++r) {
        const double v = pressures_(r, c);
        if (v < 0.0)
          throw InvalidArgument(argument, "negative pressure " + format_value(v) + " at row " +
                                              std::to_string(r) + ", column " + std::to_string(c));
      }
    }
  }

  /// Builds from any Eigen matrix expression (e.g. an integer matrix or a
  /// block of a larger recording); same checks as above.
  template <typename Derived>
  static TactileImage from(const Eigen::MatrixBase<Derived>& pressures,
                           const std::string& argument = "pressures") {
    return TactileImage(pressures.template cast<double>(), argument);
  }

  Index rows() const noexcept { return pressures_.rows(); }
  Index cols() const noexcept { return pressures_.cols(); }
  /// Number of taxels, rows() * cols().
  Index size() const noexcept { return pressures_.size(); }

  /// Pressure of taxel (row, col), raw units. Unchecked, like Eigen's `()`.
  double operator()(Index row, Index col) const noexcept { return pressures_(row, col); }

  /// The whole grid, raw units (column-major, as Eigen stores it).
  const Matrix& pressures() const noexcept { return pressures_; }

  /// Largest taxel pressure (>= 0). O(size).
  double max() const noexcept { return pressures_.maxCoeff(); }

  /// Sum of all taxel pressures (>= 0), the zeroth image moment. O(size).
  double sum() const noexcept { return pressures_.sum(); }

  /// Number of taxels whose pressure is strictly above `threshold`. O(size).
  Index count_above(double threshold) const noexcept {
    return static_cast<Index>((pressures_.array() > threshold).count());
  }

 private:
  Matrix pressures_;
};

}  // namespace iclap
