// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

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

/// The length (2 to 4) of the well-formed multi-byte UTF-8 sequence that
/// starts at `text[i]`, 1 for an ASCII byte, or 0 when the byte at `i`
/// starts no well-formed sequence (RFC 3629: no overlong forms, no
/// surrogates, nothing above U+10FFFF, no sequence cut short, no
/// continuation byte without its lead). `i` must be below text.size().
inline std::size_t utf8_sequence_length(std::string_view text, std::size_t i) noexcept {
  const auto b = static_cast<unsigned char>(text[i]);
  if (b < 0x80) return 1;
  // The sequence's length and the range of its second byte (the first
  // continuation byte is where overlong forms, surrogates and values
  // above U+10FFFF show).
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;
  if (b >= 0xC2 && b <= 0xDF) {
    n = 2;
  } else if (b >= 0xE0 && b <= 0xEF) {
    n = 3;
    if (b == 0xE0) lo = 0xA0;  // overlong below U+0800
    if (b == 0xED) hi = 0x9F;  // surrogates U+D800..U+DFFF
  } else if (b >= 0xF0 && b <= 0xF4) {
    n = 4;
    if (b == 0xF0) lo = 0x90;  // overlong below U+10000
    if (b == 0xF4) hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;  // a continuation byte, an overlong C0/C1 lead, or F5..FF
  }
  for (std::size_t k = 1; k < n; ++k) {
    if (i + k >= text.size()) return 0;
    const auto c = static_cast<unsigned char>(text[i + k]);
    if (c < (k == 1 ? lo : 0x80) || c > (k == 1 ? hi : 0xBF)) return 0;
  }
  return n;
}

/// The offset of the first byte of `text` that does not start a
/// well-formed UTF-8 sequence (see utf8_sequence_length), or
/// std::string_view::npos when the whole text is UTF-8. For a Latin-1
/// "h\xe4mmer" it is 1, the E4. O(size).
inline std::size_t utf8_error(std::string_view text) noexcept {
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t n = utf8_sequence_length(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark an editor may write at
/// the start of a UTF-8 text file. Every reader of text files here (OBJ,
/// ASCII STL, the mesh manifest, the dataset CSV and its appender, point
/// files) skips one at the start, and only there.
inline constexpr std::string_view kUtf8Bom{"\xEF\xBB\xBF", 3};

/// 3 when `text` starts with a UTF-8 byte-order mark, else 0: the offset of
/// the text proper. A second mark after the first is the text's first
/// character, not skipped.
constexpr std::size_t utf8_bom_length(std::string_view text) noexcept {
  return text.substr(0, kUtf8Bom.size()) == kUtf8Bom ? kUtf8Bom.size() : 0;
}

/// `text` without its leading UTF-8 byte-order mark, if it has one.
constexpr std::string_view without_utf8_bom(std::string_view text) noexcept {
  text.remove_prefix(utf8_bom_length(text));
  return text;
}

}  // namespace iclap
