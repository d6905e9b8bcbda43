// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <string>

namespace iclap {

/// Appends the UTF-8 encoding of the Unicode code point `c` to `out`: one to
/// four bytes. `c` must be a scalar value (at most U+10FFFF, not a
/// surrogate); callers replace or refuse others first (the HID strings with
/// U+FFFD, the mesh manifest's escapes with an error).
inline void append_utf8(std::string& out, std::uint32_t c) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
}

}  // namespace iclap
