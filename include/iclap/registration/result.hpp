// SPDX-License-Identifier: MIT
#pragma once

#include "iclap/registration/termination.hpp"
#include "iclap/registration/transform.hpp"

namespace iclap {

/// Outcome of one registration. Not converging is a normal outcome, not an
/// exception: check `converged` and `stop_reason`.
template <typename Scalar, int Dim>
struct RegistrationResult {
  /// Maps test coordinates into the model frame: x_model = R x_test + t.
  RigidTransform<Scalar, Dim> T_model_test;
  /// E = sum of squared (weighted) distances of the matched pairs under
  /// `T_model_test`, each test point matched to its closest model point
  /// (paper: E_iCLAP of Section III, minimised through Eqs. (1)-(2), and
  /// E_ICP, Eq. (8)). +infinity when no pair survived rejection.
  Scalar error = 0;
  /// sqrt(E / pairs); +infinity when there are no pairs.
  Scalar rmse = 0;
  /// Transform updates made (0 when the initial transform already met a
  /// stopping rule).
  int iterations = 0;
  /// True when a tolerance rule stopped the run.
  bool converged = false;
  StopReason stop_reason = StopReason::MaxIterations;
  /// Matched pairs at the final transform, after rejection.
  Index pairs = 0;
  /// The final pairs do not determine every moved degree of freedom (see
  /// `BlockEstimate::degenerate`); the transform is finite but arbitrary
  /// along the undetermined directions.
  bool degenerate = false;
};

}  // namespace iclap
