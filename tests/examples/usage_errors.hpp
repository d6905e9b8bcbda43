// SPDX-License-Identifier: MIT
#pragma once

// What the example programs' option parsing refuses, for checks that a bad
// option is refused naming the option and the value. (UsageError is no
// iclap::Error, so iclap::test::what_of does not read it.)

#include <string>

#include "cli.hpp"

namespace iclap::test {

/// The what() of the cli::UsageError thrown by `f`, "(no error)" when `f`
/// throws nothing (any other exception propagates, failing the test case
/// rather than passing as a message).
template <typename F>
std::string usage_error_of(F&& f) {
  try {
    f();
  } catch (const cli::UsageError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace iclap::test
