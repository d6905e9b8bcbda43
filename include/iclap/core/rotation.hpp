// SPDX-License-Identifier: MIT
#pragma once

// The one test of a rotation matrix, shared by the library
// (RigidTransform::check_rotation, an ICP guess) and the rig (a pose read
// from an arm), so that both accept the same matrices and word their
// refusals alike.

#include <limits>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>

#include "iclap/core/error.hpp"

namespace iclap {

/// How far the square matrix `q` is from orthogonal: the largest entry of
/// |q^T q - I| (0 for an orthogonal q and for a 0 x 0 one, NaN if q holds a
/// NaN or an infinity). O(n^3).
template <typename Derived>
double orthogonality_deviation(const Eigen::MatrixBase<Derived>& q) {
  const Eigen::MatrixXd m = q.template cast<double>();
  if (m.size() == 0) return 0.0;
  // Checked first: maxCoeff() keeps a NaN only where it is the first entry
  // (a NaN at (2, 2) gave 0, "orthogonal").
  if (!m.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  return (m.transpose() * m - Eigen::MatrixXd::Identity(m.rows(), m.cols())).cwiseAbs().maxCoeff();
}

/// Why a matrix with orthogonality deviation `deviation` (see
/// orthogonality_deviation) and determinant `det` is not a rotation, or ""
/// if it is one: orthogonal within `tolerance` and det > 0. The reason reads
/// after the matrix's name ("R is not orthogonal: ...").
inline std::string rotation_fault(double deviation, double det, double tolerance) {
  if (deviation <= tolerance && det > 0) return {};
  if (deviation <= tolerance) return "is orthogonal with det " + format_value(det) + " (a reflection)";
  return "is not orthogonal: the largest entry of |R^T R - I| is " + format_value(deviation) + " (tolerance " +
         format_value(tolerance) + "; det " + format_value(det) + ")";
}

/// rotation_fault of the square matrix `q` itself; a NaN or an infinity in
/// it is its own reason. O(n^3).
template <typename Derived>
std::string rotation_fault(const Eigen::MatrixBase<Derived>& q, double tolerance) {
  if (!q.allFinite()) return "holds a NaN or an infinity";
  const Eigen::MatrixXd m = q.template cast<double>();
  return rotation_fault(orthogonality_deviation(m), m.determinant(), tolerance);
}

}  // namespace iclap
