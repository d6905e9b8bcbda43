// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace iclap::rig {

/// The checksum of the Weiss WTS wire protocol (see README, "Rig tools").
///
/// A table of the CRC-16 polynomial 0x1021 built MSB-first (entry 1 = 0x1021,
/// entry 255 = 0x1EF0), initial value 0xFFFF, updated byte by byte with
/// `crc = table[(crc ^ byte) & 0xFF] ^ (crc >> 8)`, no final XOR. The table
/// and the update shift in opposite directions, so it matches no named
/// standard CRC; the golden vectors in tests/rig pin it down
/// (CRC("123456789") = 0x6EB4). Sent low byte first.
namespace crc16_detail {
constexpr std::array<std::uint16_t, 256> make_table() noexcept {
  std::array<std::uint16_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i << 8;
    for (int bit = 0; bit < 8; ++bit) c = (c & 0x8000u) ? ((c << 1) ^ 0x1021u) : (c << 1);
    table[i] = static_cast<std::uint16_t>(c & 0xFFFFu);
  }
  return table;
}
inline constexpr std::array<std::uint16_t, 256> kTable = make_table();
}  // namespace crc16_detail

/// Initial value of the WTS checksum.
inline constexpr std::uint16_t kWtsCrcInit = 0xFFFF;

/// Continues a WTS checksum `crc` over `size` bytes. O(size), no allocation,
/// thread-safe. Chain calls to checksum a message in pieces.
constexpr std::uint16_t wts_crc16_update(std::uint16_t crc, const std::uint8_t* data,
                                         std::size_t size) noexcept {
  for (std::size_t i = 0; i < size; ++i)
    crc = static_cast<std::uint16_t>(crc16_detail::kTable[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8));
  return crc;
}

/// The WTS checksum of `size` bytes (initial value 0xFFFF).
constexpr std::uint16_t wts_crc16(const std::uint8_t* data, std::size_t size) noexcept {
  return wts_crc16_update(kWtsCrcInit, data, size);
}

}  // namespace iclap::rig
