// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/error.hpp"
#include "iclap/core/types.hpp"
#include "iclap/rig/wts_protocol.hpp"

namespace iclap::rig {

/// Shape of a taxel grid: rows x columns (WTS 0614-34A: 14 x 6).
struct Grid {
  Index rows = 0;
  Index cols = 0;
  Index size() const noexcept { return rows * cols; }
  friend bool operator==(const Grid& a, const Grid& b) noexcept { return a.rows == b.rows && a.cols == b.cols; }
  friend bool operator!=(const Grid& a, const Grid& b) noexcept { return !(a == b); }
};

/// "14x6" for a Grid.
inline std::string to_string(const Grid& g) { return std::to_string(g.rows) + "x" + std::to_string(g.cols); }

/// Parses "ROWSxCOLS" (e.g. "14x6"; 'X' also accepted), each in [1, 1024].
/// Throws InvalidArgument naming `argument` and the text otherwise.
inline Grid parse_grid(const std::string& text, const std::string& argument = "grid") {
  const auto x = text.find_first_of("xX");
  const auto bad = [&](const std::string& why) { return InvalidArgument(argument, quote_text(text, 60) + " " + why); };
  if (x == std::string::npos || x == 0 || x + 1 >= text.size()) throw bad("is not ROWSxCOLS (e.g. 14x6)");
  const auto parse = [&](const std::string& part) -> Index {
    if (part.empty() || part.size() > 4 || part.find_first_not_of("0123456789") != std::string::npos)
      throw bad("is not ROWSxCOLS (e.g. 14x6)");
    const Index v = std::stoi(part);
    if (v < 1 || v > 1024) throw bad("has a side outside 1..1024");
    return v;
  };
  return Grid{parse(text.substr(0, x)), parse(text.substr(x + 1))};
}

/// The sensor's answer to "get matrix info" (0x30).
struct MatrixInfo {
  std::uint16_t res_x = 0;       ///< taxels along x; iclap reads it as the number of columns
  std::uint16_t res_y = 0;       ///< taxels along y; iclap reads it as the number of rows
  std::uint16_t cell_width = 0;  ///< taxel width, units of 1e-5 m (340 = 3.4 mm)
  std::uint16_t cell_height = 0; ///< taxel height, units of 1e-5 m
  std::uint16_t full_scale = 0;  ///< largest taxel value (4095 for 12-bit pressures)

  /// The grid as iclap reads it: rows = res_y, columns = res_x. Public
  /// sources do not settle this order (a 0614-34A is expected to report
  /// res_x = 6, res_y = 14); tools offer an override (`--grid`).
  Grid grid() const noexcept { return Grid{res_y, res_x}; }
  double cell_width_m() const noexcept { return cell_width * 1e-5; }
  double cell_height_m() const noexcept { return cell_height * 1e-5; }
};

/// Taxel values of one frame, row-major like the wire: texels(r, c) is taxel
/// row r, column c.
using TexelImage = Eigen::Matrix<std::uint16_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A tactile frame pushed by the sensor (id 0x00, uncompressed).
struct TactileFrame {
  std::uint32_t timestamp_ms = 0;  ///< sensor clock, milliseconds (wraps after ~49 days)
  std::uint8_t flags = 0;          ///< frame flags as sent, not interpreted
  /// rows x cols of raw taxel values, nominally 12-bit (0..4095); values are
  /// passed on exactly as received (the CRC vouches for them).
  TexelImage texels;

  /// The pressures as doubles (rows x cols), the dataset's units.
  Eigen::MatrixXd pressures() const { return texels.cast<double>(); }
};

/// A reply to a host command: `id` of the command, its status (0 = success)
/// and the payload after the status.
struct Reply {
  std::uint8_t id = 0;
  std::uint16_t status = 0;
  Bytes payload;
  bool ok() const noexcept { return status == 0; }
};

/// What the stream parser yields.
using WtsMessage = std::variant<TactileFrame, Reply>;

/// Decodes a successful "get matrix info" reply. Throws InvalidArgument
/// (argument "reply") if it is another reply, failed, or is too short.
inline MatrixInfo decode_matrix_info(const Reply& reply) {
  if (reply.id != wts_id::kGetMatrixInfo)
    throw InvalidArgument("reply", "is a " + wts_command_name(reply.id) + " reply, not get matrix info");
  if (!reply.ok())
    throw InvalidArgument("reply", "get matrix info failed with status " + std::to_string(reply.status));
  if (reply.payload.size() < 10)
    throw InvalidArgument("reply", "get matrix info payload has " + std::to_string(reply.payload.size()) +
                                       " bytes after the status, expected 10");
  const std::uint8_t* p = reply.payload.data();
  return MatrixInfo{get_u16(p), get_u16(p + 2), get_u16(p + 4), get_u16(p + 6), get_u16(p + 8)};
}

/// Encodes a frame the way the sensor sends it (test doubles, simulators).
inline Bytes encode_frame(const TactileFrame& frame) {
  Bytes payload;
  payload.reserve(5 + 2 * static_cast<std::size_t>(frame.texels.size()));
  put_u32(payload, frame.timestamp_ms);
  payload.push_back(frame.flags);
  for (Index r = 0; r < frame.texels.rows(); ++r)
    for (Index c = 0; c < frame.texels.cols(); ++c) put_u16(payload, frame.texels(r, c));
  return encode_packet(wts_id::kFrameData, payload);
}

/// Encodes a reply the way the sensor sends it (test doubles).
inline Bytes encode_reply(const Reply& reply) {
  Bytes payload;
  payload.reserve(2 + reply.payload.size());
  put_u16(payload, reply.status);
  payload.insert(payload.end(), reply.payload.begin(), reply.payload.end());
  return encode_packet(reply.id, payload);
}

/// Encodes a matrix info reply payload (after the status).
inline Bytes encode_matrix_info_payload(const MatrixInfo& info) {
  Bytes payload;
  for (std::uint16_t v : {info.res_x, info.res_y, info.cell_width, info.cell_height, info.full_scale})
    put_u16(payload, v);
  return payload;
}

}  // namespace iclap::rig
