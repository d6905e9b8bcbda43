// SPDX-License-Identifier: MIT
#pragma once
// Shared helpers of the dataset tests.

#include <doctest/doctest.h>

#include <sstream>
#include <string>

#include "iclap/data/data.hpp"
#include "../support/errors.hpp"

namespace iclap::test {

/// The what() ("argument: reason") of the InvalidArgument writing `d` to a
/// stream throws, "(no error)" when it is written; checks that a refused
/// dataset writes nothing and an accepted one writes something.
inline std::string writer_refusal(const Dataset& d) {
  std::ostringstream out;
  const std::string what = what_of([&] { write_dataset_csv(out, d); });
  CHECK(out.str().empty() == (what != "(no error)"));
  return what;
}

}  // namespace iclap::test
