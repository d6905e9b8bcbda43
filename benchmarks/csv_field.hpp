// SPDX-License-Identifier: MIT
// One CSV field for the study programs' result files (RFC 4180): as is when
// it holds no comma, quote or line break, otherwise quoted with inner quotes
// doubled. Setting and schedule names such as "patch ICP, 4 pts/touch" need it.
#pragma once

#include <string>
#include <string_view>

namespace iclap::bench {

inline std::string csv_field(std::string_view s) {
  if (s.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(s);
  std::string q = "\"";
  for (const char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  q += '"';
  return q;
}

}  // namespace iclap::bench
