// SPDX-License-Identifier: MIT
// The WTS codec: checksum, command encoding (golden vectors of
// shared/spec/wts-protocol.md), grids, matrix info.

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "iclap/rig/crc16.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"
#include "rig_test_util.hpp"

using namespace iclap::rig;
using iclap::rig::test::hex;

TEST_CASE("WTS CRC: table entries and golden vector") {
  using crc16_detail::kTable;
  CHECK(kTable[0] == 0x0000);
  CHECK(kTable[1] == 0x1021);
  CHECK(kTable[2] == 0x2042);
  CHECK(kTable[255] == 0x1EF0);
  const std::string digits = "123456789";
  CHECK(wts_crc16(reinterpret_cast<const std::uint8_t*>(digits.data()), digits.size()) == 0x6EB4);
  CHECK(wts_crc16(nullptr, 0) == 0xFFFF);
  // Chained updates equal one pass.
  const auto* d = reinterpret_cast<const std::uint8_t*>(digits.data());
  CHECK(wts_crc16_update(wts_crc16(d, 4), d + 4, 5) == 0x6EB4);
  static_assert(wts_crc16(nullptr, 0) == 0xFFFF, "usable in constant expressions");
}

TEST_CASE("WTS CRC: known weakness, two equal bit flips 13 bytes apart cancel") {
  // Pinned so nobody relies on the CRC alone: its update step maps two
  // states to one (kernel {0, 0xA189}), so some two-bit errors pass. The
  // parser's 12-bit range check and the tests' single-bit flips account for it.
  Bytes data(40);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 37 + 11);
  const auto crc = wts_crc16(data.data(), data.size());
  Bytes two = data;
  two[5] ^= 0x01;
  two[18] ^= 0x01;
  CHECK(wts_crc16(two.data(), two.size()) == crc);
  // Every single-bit error in this message is detected.
  for (std::size_t i = 0; i < data.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      Bytes one = data;
      one[i] ^= static_cast<std::uint8_t>(1u << bit);
      CHECK(wts_crc16(one.data(), one.size()) != crc);
    }
}

TEST_CASE("WTS commands: golden vectors") {
  CHECK(hex(encode_get_matrix_info()) == "aa aa aa 30 00 00 ca cf");
  CHECK(hex(encode_start_periodic_frames(200)) == "aa aa aa 21 03 00 00 c8 00 ed 54");
  CHECK(hex(encode_start_periodic_frames(delay_ms_for_rate(5.0))) == "aa aa aa 21 03 00 00 c8 00 ed 54");
}

namespace {
// Checks layout and CRC of an encoded command and returns its payload.
Bytes check_packet(const Bytes& packet, std::uint8_t id) {
  REQUIRE(packet.size() >= 8);
  CHECK(packet[0] == 0xAA);
  CHECK(packet[1] == 0xAA);
  CHECK(packet[2] == 0xAA);
  CHECK(packet[3] == id);
  const std::size_t size = get_u16(&packet[4]);
  REQUIRE(packet.size() == 8 + size);
  CHECK(get_u16(&packet[6 + size]) == wts_crc16(packet.data(), 6 + size));
  return Bytes(packet.begin() + 6, packet.begin() + 6 + static_cast<std::ptrdiff_t>(size));
}
}  // namespace

TEST_CASE("WTS commands: every command of the table") {
  CHECK(check_packet(encode_loop({1, 2, 3, 0xAA}), 0x06) == Bytes{1, 2, 3, 0xAA});
  CHECK(check_packet(encode_loop({}), 0x06).empty());
  CHECK(check_packet(encode_read_single_frame(), 0x20) == Bytes{0});
  CHECK(check_packet(encode_read_single_frame(true), 0x20) == Bytes{1});
  CHECK(check_packet(encode_start_periodic_frames(1000), 0x21) == Bytes{0, 0xE8, 0x03});
  CHECK(check_packet(encode_start_periodic_frames(7, true), 0x21) == Bytes{1, 7, 0});
  CHECK(check_packet(encode_stop_periodic_frames(), 0x22).empty());
  CHECK(check_packet(encode_tare(), 0x23).empty());
  CHECK(check_packet(encode_get_matrix_info(), 0x30).empty());
  CHECK(check_packet(encode_set_threshold(0x1234), 0x34) == Bytes{0x34, 0x12});
  CHECK(check_packet(encode_get_threshold(), 0x35).empty());
  CHECK(check_packet(encode_set_front_end_gain(200), 0x36) == Bytes{200});
  CHECK(check_packet(encode_get_front_end_gain(), 0x37).empty());
  CHECK(check_packet(encode_get_sensor_type(), 0x38).empty());
  CHECK(check_packet(encode_read_temperature(), 0x46).empty());
  CHECK(check_packet(encode_get_system_info(), 0x50).empty());
  CHECK(wts_command_name(0x30) == "get matrix info");
  CHECK(wts_command_name(0x7f) == "command 0x7f");
}

TEST_CASE("WTS commands: payload size limit") {
  const Bytes big(65535, 0x11);
  CHECK(check_packet(encode_packet(0x06, big), 0x06).size() == 65535);
  CHECK_THROWS_AS(encode_packet(0x06, Bytes(65536, 0)), iclap::InvalidArgument);
}

TEST_CASE("Frame rate to delay") {
  CHECK(delay_ms_for_rate(5) == 200);
  CHECK(delay_ms_for_rate(1) == 1000);
  CHECK(delay_ms_for_rate(3) == 333);
  CHECK(delay_ms_for_rate(1000) == 1);
  CHECK(delay_ms_for_rate(1000.0 / 65535.0) == 65535);
  for (double bad : {0.0, -5.0, 2000.0, 0.001, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(delay_ms_for_rate(bad), iclap::InvalidArgument);
  }
  try {
    delay_ms_for_rate(0);
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "rate");
  }
  // The rate as given (std::to_string printed 1e-9 as 0.000000).
  CHECK_THROWS_WITH_AS(delay_ms_for_rate(1e-9),
                       "rate: 1e-09 frames/s needs a delay outside the sensor's 1..65535 ms", iclap::InvalidArgument);
}

TEST_CASE("Grid parsing") {
  CHECK(parse_grid("14x6") == Grid{14, 6});
  CHECK(parse_grid("6X14") == Grid{6, 14});
  CHECK(parse_grid("1x1").size() == 1);
  for (const char* bad : {"", "14", "x6", "14x", "14x6x2", "a4x6", "0x6", "14x0", "-1x6", "2000x2", " 14x6", "14 x6"}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(parse_grid(bad, "--grid"), iclap::InvalidArgument);
  }
  try {
    parse_grid("14y6", "--grid");
    FAIL("no exception");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(std::string(e.what()).find("--grid: '14y6'") == 0);
  }
  CHECK(to_string(Grid{14, 6}) == "14x6");
}

TEST_CASE("Matrix info decoding") {
  Reply reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload({6, 14, 340, 340, 4095})};
  const MatrixInfo info = decode_matrix_info(reply);
  CHECK(info.res_x == 6);
  CHECK(info.res_y == 14);
  CHECK(info.grid() == Grid{14, 6});
  CHECK(info.cell_width_m() == doctest::Approx(0.0034));
  CHECK(info.cell_height_m() == doctest::Approx(0.0034));
  CHECK(info.full_scale == 4095);
  Reply failed = reply;
  failed.status = 3;
  CHECK_THROWS_AS(decode_matrix_info(failed), iclap::InvalidArgument);
  Reply shorter = reply;
  shorter.payload.resize(9);
  CHECK_THROWS_AS(decode_matrix_info(shorter), iclap::InvalidArgument);
  Reply other = reply;
  other.id = wts_id::kLoop;
  CHECK_THROWS_AS(decode_matrix_info(other), iclap::InvalidArgument);
}

TEST_CASE("Frame and reply encoding round trip through bytes") {
  TactileFrame f;
  f.timestamp_ms = 0x01020304;
  f.flags = 0x80;
  f.texels.resize(2, 3);
  f.texels << 1, 2, 3, 4, 5, 4095;
  const Bytes packet = encode_frame(f);
  const Bytes payload = check_packet(packet, 0x00);
  CHECK(hex(Bytes(payload.begin(), payload.begin() + 9)) == "04 03 02 01 80 01 00 02 00");
  CHECK(payload.size() == 5 + 12);
  CHECK(get_u16(&payload[5 + 10]) == 4095);  // row 1, col 2: row-major
  const Bytes r = encode_reply(Reply{0x23, 0x0005, {9}});
  CHECK(check_packet(r, 0x23) == Bytes{5, 0, 9});
}
