// SPDX-License-Identifier: MIT
#pragma once

// Export of labeled point clouds (e.g. the 4-D iCLAP reference clouds: a 3-D
// position and a codeword label per touch) as PLY, for a look in MeshLab or
// CloudCompare.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/io/atomic_file.hpp"

namespace iclap {

/// Encoding of a written PLY file.
enum class PlyEncoding {
  ascii,                 ///< readable text; numbers in shortest round-trip form
  binary_little_endian,  ///< compact; float32 positions
};

/// Options of write_labeled_cloud_ply.
struct LabeledCloudPlyOptions {
  PlyEncoding encoding = PlyEncoding::ascii;
  /// Extra `comment` lines in the header (no line breaks).
  std::vector<std::string> comments;
};

/// The colour `write_labeled_cloud_ply` gives `label`: a fixed categorical
/// palette (hues spaced by the golden angle), so neighbouring labels get
/// distinct colours and the same label always the same colour; negative
/// labels (e.g. "no word") are grey. Returns {r, g, b} in 0..255.
inline std::array<std::uint8_t, 3> label_colour(long long label) {
  if (label < 0) return {128, 128, 128};
  const double golden = 0.6180339887498949;
  double h = std::fmod(0.13 + static_cast<double>(label) * golden, 1.0) * 6.0;
  const double s = label % 2 == 0 ? 0.75 : 0.55;
  const double v = label % 3 == 0 ? 0.95 : 0.80;
  const int sector = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector) {
    case 0: r = v; g = t; b = p; break;
    case 1: r = q; g = v; b = p; break;
    case 2: r = p; g = v; b = t; break;
    case 3: r = p; g = q; b = v; break;
    case 4: r = t; g = p; b = v; break;
    default: r = v; g = p; b = q; break;
  }
  auto byte = [](double x) { return static_cast<std::uint8_t>(std::lround(x * 255.0)); };
  return {byte(r), byte(g), byte(b)};
}

namespace detail {

/// True when the integer label `v` is in the int32 range, compared in its
/// own type: a cast to long long first made std::uint64_t's largest value -1
/// (accepted, and written as label -1).
template <typename T>
bool fits_int32(const T& v) {
  if constexpr (std::is_integral_v<T>) {
    return !cmp_less(v, std::numeric_limits<std::int32_t>::min()) && !cmp_less(std::numeric_limits<std::int32_t>::max(), v);
  } else {
    // Another type convertible to an integer (an enum, say): as before.
    const long long l = static_cast<long long>(v);
    return l >= std::numeric_limits<std::int32_t>::min() && l <= std::numeric_limits<std::int32_t>::max();
  }
}

/// `v` as text for an error message: an unsigned label as unsigned (not -1).
template <typename T>
std::string label_text(const T& v) {
  if constexpr (std::is_integral_v<T> && std::is_unsigned_v<T>)
    return std::to_string(static_cast<unsigned long long>(v));
  else
    return std::to_string(static_cast<long long>(v));
}

}  // namespace detail

/// Writes a labeled point cloud as a PLY file through AtomicFileWriter (no
/// partial file on failure): one `vertex` element per column of `positions`
/// (3 x N, any unit, usually metres) with properties x, y, z (float32 in
/// binary, exact shortest text in ASCII), `label` (int32, the scalar field
/// CloudCompare shows) and red, green, blue (uchar, from label_colour, what
/// MeshLab shows). `labels` is any random-access container of integers with
/// `size()` (std::vector<int>, Eigen::VectorXi, ...), one per point.
///
/// Throws DimensionMismatch if `positions` does not have 3 rows or the label
/// count differs from the point count, NonFiniteValue for a NaN or infinite
/// coordinate, InvalidArgument for a coordinate beyond the float32 range
/// (|v| > FLT_MAX, about 3.4e38) in binary mode (it would be written as
/// inf), a label outside int32 or a comment with a line break, IoError if
/// the file cannot be written. Nothing is written when it throws. O(N).
template <typename Derived, typename Labels>
void write_labeled_cloud_ply(const std::string& path, const Eigen::MatrixBase<Derived>& positions,
                             const Labels& labels, const LabeledCloudPlyOptions& options = {}) {
  if (positions.rows() != 3) throw DimensionMismatch("positions", 3, positions.rows());
  const Eigen::Index n = positions.cols();
  if (static_cast<Eigen::Index>(labels.size()) != n)
    throw DimensionMismatch("labels", n, static_cast<Eigen::Index>(labels.size()));
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index k = 0; k < 3; ++k)
      if (!std::isfinite(static_cast<double>(positions(k, i))))
        throw NonFiniteValue("positions", k, i, static_cast<double>(positions(k, i)));
  const bool binary = options.encoding == PlyEncoding::binary_little_endian;
  if (binary) {
    // float32 positions: a finite double beyond FLT_MAX would become inf.
    const double float_max = static_cast<double>(std::numeric_limits<float>::max());
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index k = 0; k < 3; ++k) {
        const double v = static_cast<double>(positions(k, i));
        if (std::abs(v) > float_max)
          throw InvalidArgument("positions", std::string("coordinate ") + "xyz"[k] + " = " + format_value(v) +
                                                 " of point " + std::to_string(i) + " (row " + std::to_string(k) +
                                                 ", column " + std::to_string(i) +
                                                 ") is beyond the float32 range of binary PLY (|v| <= " +
                                                 format_value(float_max) + "); rescale or write ASCII");
      }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& l = labels[static_cast<decltype(labels.size())>(i)];
    if (!detail::fits_int32(l))
      throw InvalidArgument("labels", "label " + detail::label_text(l) + " of point " + std::to_string(i) +
                                          " does not fit a PLY int");
  }
  for (const auto& c : options.comments)
    if (c.find_first_of("\r\n") != std::string::npos)
      throw InvalidArgument("options.comments", "a comment contains a line break");

  std::string out = "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by iclap (labeled point cloud)\n";
  for (const auto& c : options.comments) out += "comment " + c + "\n";
  out += "element vertex " + std::to_string(n) + "\n";
  const char* coord_type = binary ? "float" : "double";
  for (const char* axis : {"x", "y", "z"}) out += std::string("property ") + coord_type + " " + axis + "\n";
  out += "property int label\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::int32_t l = static_cast<std::int32_t>(labels[static_cast<decltype(labels.size())>(i)]);
    const auto rgb = label_colour(l);
    if (binary) {
      auto put_le32 = [&out](std::uint32_t bits) {
        for (int byte = 0; byte < 4; ++byte) out += static_cast<char>((bits >> (8 * byte)) & 0xFFu);
      };
      for (Eigen::Index k = 0; k < 3; ++k) {
        const float v = static_cast<float>(positions(k, i));
        std::uint32_t bits = 0;
        std::memcpy(&bits, &v, 4);
        put_le32(bits);
      }
      put_le32(static_cast<std::uint32_t>(l));
      for (auto c : rgb) out += static_cast<char>(c);
    } else {
      for (Eigen::Index k = 0; k < 3; ++k) {
        detail::append_number(out, static_cast<double>(positions(k, i)));
        out += ' ';
      }
      detail::append_number(out, static_cast<std::int64_t>(l));
      for (auto c : rgb) {
        out += ' ';
        out += std::to_string(static_cast<int>(c));
      }
      out += '\n';
    }
  }
  AtomicFileWriter file(path, std::ios::out | std::ios::binary);
  file.stream().write(out.data(), static_cast<std::streamsize>(out.size()));
  file.commit();
}

}  // namespace iclap
