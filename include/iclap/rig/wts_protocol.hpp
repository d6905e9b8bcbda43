// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/rig/crc16.hpp"

namespace iclap::rig {

/// Bytes on the wire.
using Bytes = std::vector<std::uint8_t>;

/// Command and message ids of the Weiss WTS protocol. A reply carries the id
/// of the command it answers; pushed tactile frames carry `kFrameData`.
namespace wts_id {
inline constexpr std::uint8_t kFrameData = 0x00;           ///< frame pushed by the sensor
inline constexpr std::uint8_t kLoop = 0x06;                ///< echo of any payload
inline constexpr std::uint8_t kReadSingleFrame = 0x20;     ///< flags:u8; a frame follows the reply
inline constexpr std::uint8_t kStartPeriodicFrames = 0x21; ///< flags:u8, delay_ms:u16
inline constexpr std::uint8_t kStopPeriodicFrames = 0x22;
inline constexpr std::uint8_t kTare = 0x23;
inline constexpr std::uint8_t kGetMatrixInfo = 0x30;       ///< reply: res_x, res_y, cell_w, cell_h, full_scale (u16)
inline constexpr std::uint8_t kSetThreshold = 0x34;
inline constexpr std::uint8_t kGetThreshold = 0x35;
inline constexpr std::uint8_t kSetFrontEndGain = 0x36;
inline constexpr std::uint8_t kGetFrontEndGain = 0x37;
inline constexpr std::uint8_t kGetSensorType = 0x38;
inline constexpr std::uint8_t kReadTemperature = 0x46;
inline constexpr std::uint8_t kGetSystemInfo = 0x50;
}  // namespace wts_id

/// A readable name for a message id ("get matrix info"), or "command 0xNN".
inline std::string wts_command_name(std::uint8_t id) {
  switch (id) {
    case wts_id::kFrameData: return "frame data";
    case wts_id::kLoop: return "loop";
    case wts_id::kReadSingleFrame: return "read single frame";
    case wts_id::kStartPeriodicFrames: return "start periodic frames";
    case wts_id::kStopPeriodicFrames: return "stop periodic frames";
    case wts_id::kTare: return "tare";
    case wts_id::kGetMatrixInfo: return "get matrix info";
    case wts_id::kSetThreshold: return "set threshold";
    case wts_id::kGetThreshold: return "get threshold";
    case wts_id::kSetFrontEndGain: return "set front-end gain";
    case wts_id::kGetFrontEndGain: return "get front-end gain";
    case wts_id::kGetSensorType: return "get sensor type";
    case wts_id::kReadTemperature: return "read temperature";
    case wts_id::kGetSystemInfo: return "get system info";
    default: break;
  }
  static const char* const hex = "0123456789abcdef";
  return std::string("command 0x") + hex[id >> 4] + hex[id & 0xF];
}

/// Packet layout: `AA AA AA | id:u8 | size:u16 | payload[size] | crc:u16`,
/// little-endian, the CRC over everything before it.
inline constexpr std::uint8_t kWtsPreambleByte = 0xAA;
inline constexpr std::size_t kWtsPreambleSize = 3;
inline constexpr std::size_t kWtsHeaderSize = 6;  ///< preamble, id, size
inline constexpr std::size_t kWtsCrcSize = 2;
inline constexpr std::size_t kWtsMaxPayload = 0xFFFF;

/// Appends `value` little-endian.
inline void put_u16(Bytes& out, std::uint16_t value) {
  out.push_back(static_cast<std::uint8_t>(value & 0xFFu));
  out.push_back(static_cast<std::uint8_t>(value >> 8));
}
inline void put_u32(Bytes& out, std::uint32_t value) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<std::uint8_t>((value >> shift) & 0xFFu));
}
/// Reads a little-endian integer at `p` (caller checks the bounds).
inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

/// Whether the kWtsPreambleSize bytes at `p` are the preamble AA AA AA
/// (caller checks the bounds).
inline bool is_wts_preamble(const std::uint8_t* p) noexcept {
  return p[0] == kWtsPreambleByte && p[1] == kWtsPreambleByte && p[2] == kWtsPreambleByte;
}

/// Whether the last two of the `total` bytes at `p` (total >= kWtsCrcSize)
/// are the CRC of the bytes before them, as a packet's are.
inline bool wts_crc_matches(const std::uint8_t* p, std::size_t total) noexcept {
  return get_u16(p + total - kWtsCrcSize) == wts_crc16(p, total - kWtsCrcSize);
}

/// Whether the `size` bytes at `p` are exactly one packet: the preamble, a
/// size field that matches the length, and the CRC. Any id and payload
/// pass; PacketFramer finds such packets in a stream.
inline bool is_wts_packet(const std::uint8_t* p, std::size_t size) noexcept {
  return size >= kWtsHeaderSize + kWtsCrcSize && is_wts_preamble(p) &&
         size == kWtsHeaderSize + get_u16(p + 4) + kWtsCrcSize && wts_crc_matches(p, size);
}

/// One complete packet (preamble, id, size, payload, CRC) for message `id`.
/// Throws InvalidArgument if the payload exceeds 65535 bytes. Used for host
/// commands and, by test doubles, for the sensor's replies and frames.
inline Bytes encode_packet(std::uint8_t id, const std::uint8_t* payload, std::size_t size) {
  if (size > kWtsMaxPayload)
    throw InvalidArgument("payload", "has " + std::to_string(size) + " bytes, a WTS packet holds at most 65535");
  Bytes out;
  out.reserve(kWtsHeaderSize + size + kWtsCrcSize);
  out.insert(out.end(), kWtsPreambleSize, kWtsPreambleByte);
  out.push_back(id);
  put_u16(out, static_cast<std::uint16_t>(size));
  if (size > 0) out.insert(out.end(), payload, payload + size);
  put_u16(out, wts_crc16(out.data(), out.size()));
  return out;
}
inline Bytes encode_packet(std::uint8_t id, const Bytes& payload = {}) {
  return encode_packet(id, payload.data(), payload.size());
}

/// The sensor's delay between periodic frames for a frame rate in frames/s:
/// `delay_ms = 1000 / rate`, rounded to the nearest millisecond (5 frames/s
/// -> 200 ms). Throws InvalidArgument, naming `rate`, unless the rate is
/// finite and the delay lands in [1, 65535] ms (rate in about [0.0153, 1000]).
inline std::uint16_t delay_ms_for_rate(double rate) {
  if (!std::isfinite(rate) || rate <= 0.0)
    throw InvalidArgument("rate", format_value(rate) + " frames/s is not a positive finite rate");
  if (rate > 1000.0)
    throw InvalidArgument("rate", format_value(rate) + " frames/s is faster than the sensor's 1 ms delay allows (" +
                                      "at most 1000 frames/s)");
  const double delay = std::round(1000.0 / rate);
  if (delay > 65535.0)
    throw InvalidArgument("rate", format_value(rate) + " frames/s needs a delay of " + format_value(delay) +
                                      " ms, beyond the sensor's 65535 ms");
  return static_cast<std::uint16_t>(delay);
}

// --- Host commands. Each returns one complete packet. ---------------------

/// Loop (echo): the sensor replies with the same bytes after the status.
inline Bytes encode_loop(const Bytes& data) { return encode_packet(wts_id::kLoop, data); }

/// Read single frame: the sensor replies, then sends one frame (id 0x00).
/// iclap decodes uncompressed frames only, so `compression` defaults to off.
inline Bytes encode_read_single_frame(bool compression = false) {
  return encode_packet(wts_id::kReadSingleFrame, Bytes{static_cast<std::uint8_t>(compression ? 1 : 0)});
}

/// Start periodic frames every `delay_ms` (see delay_ms_for_rate).
inline Bytes encode_start_periodic_frames(std::uint16_t delay_ms, bool compression = false) {
  Bytes payload{static_cast<std::uint8_t>(compression ? 1 : 0)};
  put_u16(payload, delay_ms);
  return encode_packet(wts_id::kStartPeriodicFrames, payload);
}

inline Bytes encode_stop_periodic_frames() { return encode_packet(wts_id::kStopPeriodicFrames); }
/// Tare: the current load becomes the sensor's zero.
inline Bytes encode_tare() { return encode_packet(wts_id::kTare); }
inline Bytes encode_get_matrix_info() { return encode_packet(wts_id::kGetMatrixInfo); }

/// Set threshold. The team's protocol notes leave this payload open; iclap
/// sends the threshold as u16, as the WTS command set describes it.
/// Not verified on a device.
inline Bytes encode_set_threshold(std::uint16_t threshold) {
  Bytes payload;
  put_u16(payload, threshold);
  return encode_packet(wts_id::kSetThreshold, payload);
}
inline Bytes encode_get_threshold() { return encode_packet(wts_id::kGetThreshold); }

/// Set front-end gain. The payload is open in the team's notes; iclap sends
/// the gain as one byte, as the WTS command set describes it. Not verified
/// on a device.
inline Bytes encode_set_front_end_gain(std::uint8_t gain) {
  return encode_packet(wts_id::kSetFrontEndGain, Bytes{gain});
}
inline Bytes encode_get_front_end_gain() { return encode_packet(wts_id::kGetFrontEndGain); }
inline Bytes encode_get_sensor_type() { return encode_packet(wts_id::kGetSensorType); }
inline Bytes encode_read_temperature() { return encode_packet(wts_id::kReadTemperature); }
inline Bytes encode_get_system_info() { return encode_packet(wts_id::kGetSystemInfo); }

}  // namespace iclap::rig
