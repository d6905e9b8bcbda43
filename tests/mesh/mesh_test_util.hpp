// SPDX-License-Identifier: MIT
#pragma once
// Shared helpers of the mesh loader tests.

#include <doctest/doctest.h>

#include <istream>
#include <sstream>
#include <string>

#include "iclap/core/error.hpp"

namespace iclap::test {

/// "LINE: reason" of the ParseError `load(stream, name)` throws for `text`
/// (checking that it names `name`), "accepted" when it throws nothing.
template <typename Load>
std::string parse_outcome(Load&& load, const std::string& text, const std::string& name) {
  std::istringstream in(text);
  try {
    load(in, name);
  } catch (const ParseError& e) {
    CHECK(e.file() == name);
    return std::to_string(e.line()) + ": " + e.reason();
  }
  return "accepted";
}

}  // namespace iclap::test
