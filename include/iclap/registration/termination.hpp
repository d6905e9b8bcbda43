// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "iclap/core/error.hpp"

namespace iclap {

/// Why a registration stopped.
enum class StopReason {
  AbsoluteTolerance,  ///< E at or below the absolute tolerance (converged)
  RelativeTolerance,  ///< relative change of E below the threshold (converged)
  MaxIterations,      ///< the iteration cap was reached (not converged)
  NoCorrespondences,  ///< rejection left no pair (not converged)
};

/// Stable lower-case name of a stop reason ("absolute_tolerance", ...).
inline const char* to_string(StopReason r) noexcept {
  switch (r) {
    case StopReason::AbsoluteTolerance: return "absolute_tolerance";
    case StopReason::RelativeTolerance: return "relative_tolerance";
    case StopReason::MaxIterations: return "max_iterations";
    case StopReason::NoCorrespondences: return "no_correspondences";
  }
  return "unknown";
}

/// The paper's termination rules (Section III, last paragraph): stop when
/// any holds, checked in this order after each correspondence search:
///  1. E <= `absolute_tolerance`. The paper prints "E_iCLAP > preset
///     tolerance", which would stop every run at once; this is the sane
///     reading of that first rule.
///  2. |E_prev - E| < `relative_tolerance` * E_prev (the relative change
///     between two consecutive iterations falls below the threshold), or
///     E == E_prev (so that an exact fit, 0 after 0, stops here too when
///     rule 1 is disabled).
///  3. `max_iterations` transform updates have been made (n_max).
///
/// A negative absolute tolerance disables rule 1 (0 stops only at an exact
/// fit; +inf is refused, as it would stop every run before its first
/// update); a relative tolerance of 0 disables rule 2; so `max_iterations = 50`
/// with both disabled forces exactly 50 iterations.
///
/// Rounding: rule 2 also counts two consecutive errors that are both at or
/// below the registration's rounding floor (see Icp: the E that rounding
/// alone gives an exact fit) as no change. A trimmed registration of an
/// exact copy keeps a different closest fraction of its pairs at every
/// step, all at rounding distance, so E jumps between values like 1e-32
/// and 1e-34 and its relative change never falls below any threshold: it
/// used to run to `max_iterations` and report "not converged".
///
/// A custom termination policy provides `void validate() const` and
/// `std::optional<StopReason> check(int iterations, Scalar E, Scalar E_prev) const`
/// (E_prev is meaningless when iterations == 0); a registration calls
/// `check(iterations, E, E_prev, floor)` instead where the policy has it.
template <typename Scalar>
struct PaperTermination {
  int max_iterations = 50;
  Scalar absolute_tolerance = 0;
  Scalar relative_tolerance = Scalar(1e-6);

  void validate() const {
    if (max_iterations < 0)
      throw InvalidArgument("termination.max_iterations", "must be >= 0 (got " + std::to_string(max_iterations) + ")");
    if (std::isnan(absolute_tolerance))
      throw InvalidArgument("termination.absolute_tolerance", "must not be NaN");
    if (absolute_tolerance == std::numeric_limits<Scalar>::infinity())
      throw InvalidArgument("termination.absolute_tolerance",
                            "must not be +inf: every registration would stop at its initial transform, reported as "
                            "converged");
    if (!(relative_tolerance >= 0) || !std::isfinite(relative_tolerance))
      throw InvalidArgument("termination.relative_tolerance", "must be finite and >= 0 (got " + format_exact(relative_tolerance) + ")");
  }

  /// The rules without a rounding floor (floor 0: only equal errors).
  std::optional<StopReason> check(int iterations, Scalar error, Scalar previous_error) const {
    return check(iterations, error, previous_error, Scalar(0));
  }

  /// The rules, with `floor` the E that rounding alone gives an exact fit
  /// of these clouds (>= 0).
  std::optional<StopReason> check(int iterations, Scalar error, Scalar previous_error, Scalar floor) const {
    if (error <= absolute_tolerance) return StopReason::AbsoluteTolerance;
    if (iterations > 0 && relative_tolerance > 0 &&
        (error == previous_error || std::abs(previous_error - error) < relative_tolerance * previous_error ||
         (error <= floor && previous_error <= floor)))
      return StopReason::RelativeTolerance;
    if (iterations >= max_iterations) return StopReason::MaxIterations;
    return std::nullopt;
  }
};

}  // namespace iclap
