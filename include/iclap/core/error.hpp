// SPDX-License-Identifier: MIT
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <typeinfo>
#include <utility>

#include "iclap/core/utf8.hpp"

namespace iclap {

/// Base of every exception the library throws. Catch this to catch them all.
///
/// Misuse (NaN input, empty clouds, impossible settings) and unreadable files
/// are exceptions; a registration that does not converge is not, it is a
/// normal outcome reported in the result.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A caller passed a value the contract does not allow. `argument()` names
/// the parameter (or the setting, e.g. "settings.trim_fraction"),
/// `reason()` what is wrong with it; `what()` reads "argument: reason".
class InvalidArgument : public Error {
 public:
  InvalidArgument(std::string argument, std::string reason)
      : Error(argument + ": " + reason), argument_(std::move(argument)), reason_(std::move(reason)) {}
  const std::string& argument() const noexcept { return argument_; }
  const std::string& reason() const noexcept { return reason_; }

  /// A copy of this error, of its own type (EmptyInput, NonFiniteValue, ...)
  /// and with its data and reason, that names `argument` instead: what
  /// rename_argument throws. A class derived from InvalidArgument overrides
  /// it as the library's do (`return renamed_copy(*this,
  /// std::move(argument));`); for one that does not, it returns null rather
  /// than a copy cut down to a base class.
  virtual std::exception_ptr renamed(std::string argument) const { return renamed_copy(*this, std::move(argument)); }

 protected:
  /// `e` (of static type E) copied and naming `argument`; null if E is not
  /// e's dynamic type.
  template <typename E>
  static std::exception_ptr renamed_copy(const E& e, std::string argument) {
    if (typeid(e) != typeid(E)) return nullptr;
    E copy(e);
    InvalidArgument& base = copy;
    base.Error::operator=(Error(argument + ": " + base.reason_));
    base.argument_ = std::move(argument);
    return std::make_exception_ptr(std::move(copy));
  }

 private:
  std::string argument_;
  std::string reason_;
};

/// An input that must hold at least one element holds none.
class EmptyInput : public InvalidArgument {
 public:
  explicit EmptyInput(std::string argument, const std::string& what_is_empty = "is empty")
      : InvalidArgument(std::move(argument), what_is_empty) {}
  std::exception_ptr renamed(std::string argument) const override { return renamed_copy(*this, std::move(argument)); }
};

/// Two inputs (or an input and a compile-time size) disagree on a dimension.
class DimensionMismatch : public InvalidArgument {
 public:
  DimensionMismatch(std::string argument, std::ptrdiff_t expected, std::ptrdiff_t actual)
      : InvalidArgument(std::move(argument), "has dimension " + std::to_string(actual) +
                                                 ", expected " + std::to_string(expected)),
        expected_(expected),
        actual_(actual) {}
  std::ptrdiff_t expected() const noexcept { return expected_; }
  std::ptrdiff_t actual() const noexcept { return actual_; }
  std::exception_ptr renamed(std::string argument) const override { return renamed_copy(*this, std::move(argument)); }

 private:
  std::ptrdiff_t expected_;
  std::ptrdiff_t actual_;
};

/// A NaN or infinity where a finite number is required. `row()` and `column()`
/// locate it (for point clouds: coordinate and point index).
class NonFiniteValue : public InvalidArgument {
 public:
  NonFiniteValue(std::string argument, std::ptrdiff_t row, std::ptrdiff_t column, double value)
      : InvalidArgument(std::move(argument), "non-finite value " + std::to_string(value) +
                                                 " at row " + std::to_string(row) +
                                                 ", column " + std::to_string(column)),
        row_(row),
        column_(column) {}
  std::ptrdiff_t row() const noexcept { return row_; }
  std::ptrdiff_t column() const noexcept { return column_; }
  std::exception_ptr renamed(std::string argument) const override { return renamed_copy(*this, std::move(argument)); }

 private:
  std::ptrdiff_t row_;
  std::ptrdiff_t column_;
};

/// The name `name` gives: `name` itself (a string), or what it returns (a
/// callable). Lets a function take an argument's name that is built only
/// when an error names it, as rename_argument and normalize do.
template <typename Name>
std::string argument_name(const Name& name) {
  if constexpr (std::is_invocable_v<const Name&>) return std::string(name());
  else return std::string(name);
}

namespace detail {

/// Returns `f()`; an InvalidArgument (or an error derived from it) for
/// whose name `rename` gives a new one (a std::optional<std::string>) is
/// thrown again under it, of the same type, with the same reason and data
/// (InvalidArgument::renamed). Everything else passes as it is.
template <typename F, typename Rename>
decltype(auto) rename_invalid_argument(F&& f, const Rename& rename) {
  try {
    return std::forward<F>(f)();
  } catch (const InvalidArgument& e) {
    std::optional<std::string> name = rename(std::string_view(e.argument()));
    if (!name) throw;
    const std::exception_ptr copy = e.renamed(std::move(*name));
    if (!copy) throw;  // of a derived class without its own renamed()
    std::rethrow_exception(copy);
  }
}

}  // namespace detail

/// Returns `f()`; an InvalidArgument naming `from` is thrown again naming
/// `to`, with the same reason. Lets a caller give a callee's parameter
/// ("image", "settings.voxel") the name its own user knows ("images[3]",
/// "voxel"). Derived errors (EmptyInput, DimensionMismatch, NonFiniteValue)
/// are renamed too and keep their type and data; other arguments and other
/// exceptions pass through as they are. `to` is a string, or a callable
/// returning one, called only when an error is renamed (so a name such as
/// "images[j]" costs nothing on the normal path).
template <typename To, typename F>
decltype(auto) rename_argument(std::string_view from, const To& to, F&& f) {
  return detail::rename_invalid_argument(std::forward<F>(f), [&](std::string_view name) -> std::optional<std::string> {
    if (name != from) return std::nullopt;
    return argument_name(to);
  });
}

/// Returns `f()`; an InvalidArgument (or derived error, which keeps its
/// type) whose name starts with `from_prefix` is thrown again with that
/// prefix replaced by `to_prefix`, with the same reason: a nested settings
/// object's errors ("settings.leaf_max_size") named as its owner's user set
/// them ("settings.search.leaf_max_size"). Everything else passes as it is,
/// as for rename_argument.
template <typename F>
decltype(auto) rename_argument_prefix(std::string_view from_prefix, std::string_view to_prefix, F&& f) {
  return detail::rename_invalid_argument(std::forward<F>(f), [&](std::string_view name) -> std::optional<std::string> {
    if (name.substr(0, from_prefix.size()) != from_prefix) return std::nullopt;
    return std::string(to_prefix).append(name.substr(from_prefix.size()));
  });
}

/// A file or stream could not be parsed. `what()` reads "FILE:LINE: reason",
/// the form compilers use, so editors and terminals can jump to the line.
/// Readers that throw it return nothing partial.
class ParseError : public Error {
 public:
  ParseError(std::string file, std::size_t line, std::string reason)
      : Error(file + ":" + std::to_string(line) + ": " + reason),
        file_(std::move(file)),
        line_(line),
        reason_(std::move(reason)) {}
  const std::string& file() const noexcept { return file_; }
  /// 1-based line number; 0 when the problem concerns the whole file.
  std::size_t line() const noexcept { return line_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string reason_;
};

/// The operating system refused a file or device operation.
class IoError : public Error {
 public:
  IoError(std::string path, const std::string& reason)
      : Error(path + ": " + reason), path_(std::move(path)) {}
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

/// Writing output failed part-way (disk full, file size limit, device
/// gone): not a problem of the input, unlike a file that cannot be opened.
/// The writer that throws it says what it left behind (the library's
/// writers leave nothing partial).
class WriteError : public IoError {
 public:
  using IoError::IoError;
};

/// A number for a message or a label: 6 significant digits in the shorter
/// of fixed and exponent notation (1e-310, not std::to_string's 0.000000).
inline std::string format_value(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// A number for a message about a setting that must lie in a range: the
/// shortest text that reads back to exactly `v` in its own type (float or
/// double; std::to_chars), so a value just outside the range never looks
/// like one inside it (1.0000001f, not format_value's "1").
template <typename T>
std::string format_exact(T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// Is `b` a control byte (below 0x20, or 0x7f)?
inline bool is_control_byte(unsigned char b) { return b < 0x20 || b == 0x7f; }

/// `text` for a message or a terminal, unquoted: every control character
/// (the bytes below 0x20 and 0x7f, and the C1 controls U+0080..U+009F, such
/// as U+009B, which some terminals take for an escape sequence) and every
/// byte that is not part of a well-formed UTF-8 sequence (a Latin-1 \xe4, a
/// cut character) written as \xNN, so a NUL in the input cannot cut a
/// message short, a carriage return cannot overwrite it on a terminal, a
/// line break cannot forge a line, and the text is UTF-8 whatever the
/// input. Other UTF-8 characters (names like "zange_m\xc3\xbcller") are
/// kept. With `max_bytes` > 0, a longer text is cut after at most max_bytes
/// of its bytes (never inside a character) and ends in "...".
inline std::string escape_text(std::string_view text, std::size_t max_bytes = 0) {
  const bool cut = max_bytes > 0 && text.size() > max_bytes;
  const std::size_t limit = cut ? max_bytes : text.size();
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  const auto hex = [&](char c) {
    const auto b = static_cast<unsigned char>(c);
    out += "\\x";
    out += kHex[b >> 4];
    out += kHex[b & 0xf];
  };
  for (std::size_t i = 0; i < limit;) {
    const std::size_t n = utf8_sequence_length(text, i);
    if (n > 1) {  // a whole character, kept if it fits
      if (i + n > limit) break;
      // C2 80..C2 9F: a C1 control, escaped as its two bytes.
      const bool c1 = n == 2 && static_cast<unsigned char>(text[i]) == 0xC2 &&
                      static_cast<unsigned char>(text[i + 1]) < 0xA0;
      if (c1) {
        hex(text[i]);
        hex(text[i + 1]);
      } else {
        out.append(text.substr(i, n));
      }
      i += n;
      continue;
    }
    if (n == 0 || is_control_byte(static_cast<unsigned char>(text[i]))) {
      hex(text[i]);
    } else {
      out += text[i];
    }
    ++i;
  }
  return cut ? out + "..." : out;
}

/// `text` quoted for an error message: 'text', escaped as escape_text
/// writes it (control characters and bytes that are not UTF-8 as \xNN;
/// with `max_bytes` > 0 cut after at most max_bytes bytes, ending in "...").
inline std::string quote_text(std::string_view text, std::size_t max_bytes = 0) {
  return "'" + escape_text(text, max_bytes) + "'";
}

}  // namespace iclap
