// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// The `--touches` list of `iclap evaluate` (and of the benchmark programs
/// that mirror its protocol): numbers of touches per test.

#include <set>
#include <string>
#include <vector>

#include "cli.hpp"

namespace iclap::cli {

/// "1,5,10,20" or "1..20" (ranges and single counts may be mixed), each
/// count in [1, 100000]; UsageError naming --touches for a bad number, an
/// empty range or a count listed twice. The counts are returned in
/// increasing order whatever the order given: the tables, the CSV files and
/// the figures (lines drawn from count to count, the three-term weight
/// figure at the largest count) take them in that order.
inline std::vector<int> parse_touches(const std::string& text) {
  std::vector<int> out;
  for (const auto& part : Options::split(text, ',')) {
    const auto dots = part.find("..");
    if (dots != std::string::npos) {
      const auto a = Options::parse_integer(part.substr(0, dots), "--touches", 1, 100000);
      const auto b = Options::parse_integer(part.substr(dots + 2), "--touches", 1, 100000);
      if (b < a) throw UsageError("--touches: empty range '" + part + "'");
      for (long long t = a; t <= b; ++t) out.push_back(static_cast<int>(t));
    } else {
      out.push_back(static_cast<int>(Options::parse_integer(part, "--touches", 1, 100000)));
    }
  }
  std::set<int> seen;
  for (int t : out)
    if (!seen.insert(t).second) throw UsageError("--touches: " + std::to_string(t) + " is listed twice");
  return std::vector<int>(seen.begin(), seen.end());
}

}  // namespace iclap::cli
