// SPDX-License-Identifier: MIT
#pragma once

// What an iclap error names or says, for checks that a bad input is refused
// under the right name and for the right reason.

#include <exception>
#include <string>
#include <type_traits>

#include "iclap/core/error.hpp"

namespace iclap::test {

/// The argument the InvalidArgument thrown by `f` names, "(no error)" when
/// `f` throws nothing (any other exception propagates).
template <typename F>
std::string argument_of(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.argument();
  }
  return "(no error)";
}

/// The what() of the E (an exception type: InvalidArgument unless given,
/// e.g. cli::UsageError for the example programs' options) thrown by `f`,
/// "(no error)" when `f` throws nothing (any other exception propagates,
/// failing the test case rather than passing as a message).
template <typename E = InvalidArgument, typename F>
std::string what_of(F&& f) {
  static_assert(std::is_base_of_v<std::exception, E>, "what_of reads exceptions");
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace iclap::test
