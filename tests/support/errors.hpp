// SPDX-License-Identifier: MIT
#pragma once

// What an iclap error names, for checks that a bad input is refused under
// the right name.

#include <string>

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

}  // namespace iclap::test
