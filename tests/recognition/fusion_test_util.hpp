// SPDX-License-Identifier: MIT
// Helpers of the fusion and method tests (test_fusion.cpp,
// test_recognition_audit.cpp, one executable).
#pragma once

#include <initializer_list>
#include <string>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"

namespace iclap::test {

/// A vector of distances, one per object.
inline Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Index>(v.size()));
  Index i = 0;
  for (double d : v) x(i++) = d;
  return x;
}

/// "ARGUMENT | WHAT" of the InvalidArgument `f` throws, "(no error)" when
/// it throws nothing.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return std::string(e.argument()) + " | " + e.what();
  }
  return "(no error)";
}

}  // namespace iclap::test
