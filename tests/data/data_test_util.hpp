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

/// The 1 x 2 frame the appender cases append: object "b", exploration 4,
/// frame 1, at (1, 2, 3), pressures 5 and 6.
inline Frame appended_frame() {
  Frame f;
  f.object = "b";
  f.exploration = 4;
  f.frame = 1;
  f.position = {1, 2, 3};
  f.pressures.resize(1, 2);
  f.pressures << 5, 6;
  return f;
}

}  // namespace iclap::test
