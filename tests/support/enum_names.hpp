// SPDX-License-Identifier: MIT
#pragma once
// Checks an enumeration's to_string: each listed value has its documented
// name, no two share one, and a value outside the enumeration (a cast from a
// corrupt setting) reads "unknown", never a null pointer nor another value's
// name.

#include <doctest/doctest.h>

#include <cstddef>
#include <set>
#include <string>
#include <utility>

namespace iclap::test {

template <typename Enum, std::size_t N>
void check_enum_names(const std::pair<Enum, std::string> (&names)[N], Enum outside) {
  std::set<std::string> seen;
  for (const auto& entry : names) {
    const std::string& name = entry.second;
    CAPTURE(name);
    const char* got = to_string(entry.first);
    REQUIRE(got != nullptr);
    CHECK(std::string(got) == name);
    CHECK(seen.insert(got).second);
  }
  CHECK(seen.size() == N);
  const char* other = to_string(outside);
  REQUIRE(other != nullptr);
  CHECK(std::string(other) == "unknown");
}

}  // namespace iclap::test
