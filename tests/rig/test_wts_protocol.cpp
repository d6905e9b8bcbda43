// SPDX-License-Identifier: MIT
// The WTS codec: checksum, command encoding (golden vectors of
// shared/spec/wts-protocol.md), command names, grids, matrix info; WtsSensor
// over a scripted in-memory stream (frame queue, command checks, stopping).

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "iclap/rig/crc16.hpp"
#include "iclap/rig/wts_message.hpp"
#include "iclap/rig/wts_protocol.hpp"
#include "iclap/rig/wts_sensor.hpp"
#include "rig_test_util.hpp"
#include "../support/errors.hpp"

using namespace iclap::rig;
using iclap::rig::test::hex;
using namespace std::chrono_literals;

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

TEST_CASE("is_wts_packet: every encoded packet, and nothing one bit or one byte away") {
  const Bytes packets[] = {encode_loop({}), encode_tare(), encode_loop({1, 2, 3, 0xAA, 0xAA, 0xAA}),
                           encode_start_periodic_frames(200), encode_packet(0x00, Bytes(173, 0x5A))};
  for (const Bytes& p : packets) {
    CAPTURE(hex(Bytes(p.begin(), p.begin() + 6)));
    CHECK(is_wts_packet(p.data(), p.size()));
    CHECK(is_wts_preamble(p.data()));
    CHECK(wts_crc_matches(p.data(), p.size()));
    // Every single-bit error: in the preamble, the size field (the length
    // no longer matches) or anywhere the CRC covers (CRC-16 catches it).
    int accepted = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int bit = 0; bit < 8; ++bit) {
        Bytes q = p;
        q[i] ^= static_cast<std::uint8_t>(1u << bit);
        accepted += is_wts_packet(q.data(), q.size()) ? 1 : 0;
      }
    CHECK(accepted == 0);
    // A byte short or a byte more (one packet, not a prefix or a stream).
    for (std::size_t n = 0; n < p.size(); ++n) CHECK_FALSE(is_wts_packet(p.data(), n));
    Bytes longer = p;
    longer.push_back(0);
    CHECK_FALSE(is_wts_packet(longer.data(), longer.size()));
  }
  const std::uint8_t not_preamble[] = {0xAA, 0xAA, 0xAB};
  CHECK_FALSE(is_wts_preamble(not_preamble));
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
  CHECK_THROWS_WITH_AS(delay_ms_for_rate(1e-9), "rate: 1e-09 frames/s needs a delay of 1e+12 ms, beyond the sensor's 65535 ms",
                       iclap::InvalidArgument);
  // Just above 1000 frames/s the delay would round to 1 ms, inside the
  // range: the message says what is wrong, the rate (it used to claim a
  // delay outside 1..65535 ms).
  CHECK(delay_ms_for_rate(1000.0) == 1);
  CHECK_THROWS_WITH_AS(delay_ms_for_rate(1000.4),
                       "rate: 1000.4 frames/s is faster than the sensor's 1 ms delay allows (at most 1000 frames/s)",
                       iclap::InvalidArgument);
}

TEST_CASE("Frame rate to delay: rounded to the nearest millisecond; a rate of 0 is named as not positive") {
  // delay_ms = 1000 / rate (shared/spec/wts-protocol.md), rounded, not truncated.
  CHECK(delay_ms_for_rate(6) == 167);  // 166.67
  CHECK(delay_ms_for_rate(7) == 143);  // 142.86
  CHECK(delay_ms_for_rate(9) == 111);  // 111.11
  CHECK_THROWS_WITH_AS(delay_ms_for_rate(0), "rate: 0 frames/s is not a positive finite rate", iclap::InvalidArgument);
  CHECK_THROWS_WITH_AS(delay_ms_for_rate(-5), "rate: -5 frames/s is not a positive finite rate", iclap::InvalidArgument);
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

TEST_CASE("Grid parsing: sides up to 1024; a number too long for an int is refused, not overflowed") {
  CHECK(parse_grid("1024x1024") == Grid{1024, 1024});
  CHECK_THROWS_WITH_AS(parse_grid("1025x6", "--grid"), "--grid: '1025x6' has a side outside 1..1024",
                       iclap::InvalidArgument);
  for (const std::string bad : {"99999999999x6", "14x99999999999999999999"}) {
    CAPTURE(bad);
    CHECK_THROWS_WITH_AS(parse_grid(bad, "--grid"), ("--grid: '" + bad + "' is not ROWSxCOLS (e.g. 14x6)").c_str(),
                         iclap::InvalidArgument);
  }
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

TEST_CASE("Matrix info decoding: the spec's field order, from the bytes") {
  // res_x, res_y, cell_w, cell_h, full_scale, u16 little-endian each
  // (shared/spec/wts-protocol.md), with cell width and height told apart.
  const Bytes wire{6, 0, 14, 0, 0x54, 0x01, 0x2C, 0x01, 0xFF, 0x0F};  // 6, 14, 340, 300, 4095
  const MatrixInfo info = decode_matrix_info(Reply{wts_id::kGetMatrixInfo, 0, wire});
  CHECK(info.res_x == 6);
  CHECK(info.res_y == 14);
  CHECK(info.cell_width == 340);
  CHECK(info.cell_height == 300);
  CHECK(info.full_scale == 4095);
  CHECK(info.cell_width_m() == doctest::Approx(0.0034));
  CHECK(info.cell_height_m() == doctest::Approx(0.0030));
  CHECK(encode_matrix_info_payload(info) == wire);
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

TEST_CASE("WTS command names: each id has its own, the protocol spec's") {
  // shared/spec/wts-protocol.md, "Commands": id and name.
  const std::pair<std::uint8_t, std::string> spec[] = {
      {0x00, "frame data"},         {0x06, "loop"},
      {0x20, "read single frame"},  {0x21, "start periodic frames"},
      {0x22, "stop periodic frames"}, {0x23, "tare"},
      {0x30, "get matrix info"},    {0x34, "set threshold"},
      {0x35, "get threshold"},      {0x36, "set front-end gain"},
      {0x37, "get front-end gain"}, {0x38, "get sensor type"},
      {0x46, "read temperature"},   {0x50, "get system info"},
  };
  const std::uint8_t ids[] = {wts_id::kFrameData,       wts_id::kLoop,           wts_id::kReadSingleFrame,
                              wts_id::kStartPeriodicFrames, wts_id::kStopPeriodicFrames, wts_id::kTare,
                              wts_id::kGetMatrixInfo,   wts_id::kSetThreshold,   wts_id::kGetThreshold,
                              wts_id::kSetFrontEndGain, wts_id::kGetFrontEndGain, wts_id::kGetSensorType,
                              wts_id::kReadTemperature, wts_id::kGetSystemInfo};
  REQUIRE(std::size(ids) == std::size(spec));
  for (std::size_t i = 0; i < std::size(spec); ++i) {
    CAPTURE(i);
    CHECK(ids[i] == spec[i].first);
    CHECK(wts_command_name(ids[i]) == spec[i].second);
  }
  // Every one of the 256 ids has a non-empty name of its own; ids without a
  // command read "command 0xNN" (two lower-case hex digits).
  std::set<std::string> names;
  for (int id = 0; id < 256; ++id) {
    CAPTURE(id);
    const std::string name = wts_command_name(static_cast<std::uint8_t>(id));
    CHECK_FALSE(name.empty());
    CHECK(names.insert(name).second);
    const bool named = std::any_of(std::begin(spec), std::end(spec), [&](const auto& c) { return c.first == id; });
    if (named) continue;
    char expected[16];
    std::snprintf(expected, sizeof expected, "command 0x%02x", static_cast<unsigned>(id));
    CHECK(name == expected);
  }
  CHECK(names.size() == 256);
}

namespace {

// A 2x3 frame whose taxels all read `timestamp_ms` (so frames are told apart).
TactileFrame numbered_frame(std::uint32_t timestamp_ms) {
  return test::flat_frame(timestamp_ms, static_cast<std::uint16_t>(timestamp_ms));
}

WtsSensor::Settings grid_2x3() {
  WtsSensor::Settings st;
  st.parser.grid = Grid{2, 3};
  return st;
}

}  // namespace

TEST_CASE("WtsSensor: frames beyond the queue while a reply is awaited drop the oldest, counted") {
  test::MemoryStream s("scripted");
  WtsSensor::Settings st = grid_2x3();
  st.max_queued_frames = 3;
  WtsSensor sensor(s, st);
  // Seven frames reach the host before the reply to "tare".
  for (std::uint32_t t = 1; t <= 7; ++t) s.push(encode_frame(numbered_frame(t)));
  s.push(encode_reply(Reply{wts_id::kTare, 0, {}}));
  const Reply reply = sensor.request(encode_tare());
  CHECK(reply.id == wts_id::kTare);
  CHECK(reply.ok());
  CHECK(sensor.frames_overflowed() == 4);
  // The newest three are kept, in order.
  for (std::uint32_t t : {5u, 6u, 7u}) {
    CAPTURE(t);
    const auto f = sensor.next_frame(0ms);
    REQUIRE(f);
    CHECK(f->timestamp_ms == t);
    CHECK((f->texels.array() == static_cast<std::uint16_t>(t)).all());
  }
  CHECK_FALSE(sensor.next_frame(0ms));
  // The count adds up over requests; a reader that keeps up loses nothing.
  for (std::uint32_t t = 8; t <= 11; ++t) s.push(encode_frame(numbered_frame(t)));
  s.push(encode_reply(Reply{wts_id::kTare, 0, {}}));
  sensor.request(encode_tare());
  CHECK(sensor.frames_overflowed() == 5);
  for (std::uint32_t t = 12; t <= 20; ++t) s.push(encode_frame(numbered_frame(t)));
  std::vector<std::uint32_t> read;
  while (const auto f = sensor.next_frame(0ms)) read.push_back(f->timestamp_ms);
  CHECK(read == std::vector<std::uint32_t>{9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20});
  CHECK(sensor.frames_overflowed() == 5);
  CHECK(s.written == std::vector<Bytes>{encode_tare(), encode_tare()});
}

TEST_CASE("WtsSensor: a command that is not an encoded packet is refused, nothing sent") {
  test::MemoryStream s("scripted");
  WtsSensor::Settings st = grid_2x3();
  st.reply_timeout = 1ms;  // a command sent by mistake times out at once
  st.attempts = 1;
  WtsSensor sensor(s, st);
  // `body` and its CRC: each packet below is wrong in one way only.
  const auto with_crc = [](Bytes body) {
    put_u16(body, wts_crc16(body.data(), body.size()));
    return body;
  };
  const Bytes tare = encode_tare();
  Bytes bad_crc = encode_loop({1, 2, 3});
  bad_crc.back() ^= 0x01;
  const std::pair<const char*, Bytes> bad[] = {
      {"empty", Bytes{}},
      {"shorter than a header and CRC", Bytes(tare.begin(), tare.end() - 1)},
      {"first preamble byte", with_crc({0x55, 0xAA, 0xAA, 0x23, 0, 0})},
      {"second preamble byte", with_crc({0xAA, 0xAB, 0xAA, 0x23, 0, 0})},
      {"third preamble byte", with_crc({0xAA, 0xAA, 0x00, 0x23, 0, 0})},
      {"payload shorter than its size field", with_crc({0xAA, 0xAA, 0xAA, 0x06, 3, 0, 1, 2})},
      {"payload longer than its size field", with_crc({0xAA, 0xAA, 0xAA, 0x06, 1, 0, 1, 2})},
      {"wrong CRC", bad_crc},
  };
  for (const auto& c : bad) {
    const std::string what = c.first;
    const Bytes& command = c.second;
    CAPTURE(what);
    CHECK_THROWS_WITH_AS(sensor.request(command), "command: is not an encoded WTS packet", iclap::InvalidArgument);
    CHECK_THROWS_WITH_AS(sensor.request_ok(command), "command: is not an encoded WTS packet", iclap::InvalidArgument);
  }
  CHECK(s.write_calls == 0);
  // A real packet goes out as it is.
  s.push(encode_reply(Reply{wts_id::kLoop, 0, {1, 2, 3}}));
  CHECK(sensor.request_ok(encode_loop({1, 2, 3})).payload == Bytes{1, 2, 3});
  CHECK(s.written == std::vector<Bytes>{encode_loop({1, 2, 3})});
}

TEST_CASE("WtsSensor: stop_periodic_frames is false when the sensor refuses or stays silent") {
  test::MemoryStream s("scripted");
  WtsSensor::Settings st = grid_2x3();
  st.reply_timeout = 1ms;
  st.attempts = 2;
  WtsSensor sensor(s, st);
  s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 0, {}}));
  sensor.start_periodic_frames(5.0);
  CHECK(sensor.streaming());
  // Refused (status 3): the error request_ok() throws names the command ...
  s.push(encode_reply(Reply{wts_id::kStopPeriodicFrames, 3, {}}));
  try {
    sensor.request_ok(encode_stop_periodic_frames());
    FAIL_CHECK("a refusal was accepted");
  } catch (const WtsCommandError& e) {
    CHECK(e.id() == wts_id::kStopPeriodicFrames);
    CHECK(e.status() == 3);
    CHECK(std::string(e.what()) == "sensor refused 'stop periodic frames' with status 3");
  }
  // ... and stop_periodic_frames() reports it as false; the sensor may
  // still stream, so the destructor would send the stop again.
  s.push(encode_reply(Reply{wts_id::kStopPeriodicFrames, 3, {}}));
  CHECK_FALSE(sensor.stop_periodic_frames());
  CHECK(sensor.streaming());
  // Silent: false after every attempt (request() would time out).
  const std::size_t sent = s.written.size();
  CHECK_FALSE(sensor.stop_periodic_frames());
  CHECK(s.written.size() == sent + 2);
  CHECK(s.written.back() == encode_stop_periodic_frames());
  CHECK_THROWS_WITH_AS(sensor.request(encode_stop_periodic_frames()),
                       "scripted: no reply to 'stop periodic frames' after 2 attempt(s) of 1 ms", WtsTimeout);
  // Acknowledged: true, and no longer streaming.
  s.push(encode_reply(Reply{wts_id::kStopPeriodicFrames, 0, {}}));
  CHECK(sensor.stop_periodic_frames());
  CHECK_FALSE(sensor.streaming());
  CHECK_FALSE(sensor.lost());
}

TEST_CASE("WtsSensor: the destructor's stop command is best effort") {
  test::MemoryStream s("scripted");
  {
    WtsSensor sensor(s, grid_2x3());
    s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 0, {}}));
    sensor.start_periodic_frames(5.0);
    REQUIRE(sensor.streaming());
    s.gone = true;  // the stop command's write throws DeviceLost: ignored
  }
  CHECK(s.write_calls == 2);  // start, then the attempted stop
  // Without a stream it started, the destructor sends nothing.
  s.gone = false;
  { WtsSensor idle(s, grid_2x3()); }
  CHECK(s.write_calls == 2);
}

TEST_CASE("WtsSensor: settings without an attempt or a reply timeout are refused, naming the setting") {
  test::MemoryStream s("scripted");
  const auto refused = [&](const WtsSensor::Settings& st) {
    return iclap::test::argument_of([&] { WtsSensor sensor(s, st); });
  };
  for (int attempts : {0, -1}) {
    CAPTURE(attempts);
    WtsSensor::Settings st = grid_2x3();
    st.attempts = attempts;
    CHECK(refused(st) == "settings.attempts");
  }
  for (const auto timeout : {0ms, -5ms}) {
    CAPTURE(timeout.count());
    WtsSensor::Settings st = grid_2x3();
    st.reply_timeout = timeout;
    CHECK(refused(st) == "settings.reply_timeout");
  }
  WtsSensor::Settings least = grid_2x3();
  least.attempts = 1;
  least.reply_timeout = 1ms;
  CHECK(refused(least) == "(no error)");
  CHECK(s.write_calls == 0);
}

TEST_CASE("WtsSensor: replies to other commands are ignored while a reply is awaited") {
  test::MemoryStream s("scripted");
  WtsSensor sensor(s, grid_2x3());
  s.push(encode_reply(Reply{wts_id::kLoop, 0, {9}}));                // nobody waits for it
  s.push(encode_reply(Reply{wts_id::kStopPeriodicFrames, 3, {}}));  // nor for this one
  s.push(encode_frame(numbered_frame(1)));
  s.push(encode_reply(Reply{wts_id::kTare, 0, {}}));
  const Reply reply = sensor.request_ok(encode_tare());
  CHECK(reply.id == wts_id::kTare);
  CHECK(reply.ok());
  CHECK(reply.payload.empty());
  const auto f = sensor.next_frame(0ms);  // the frame that came with them is kept
  REQUIRE(f);
  CHECK(f->timestamp_ms == 1);
  CHECK_FALSE(sensor.next_frame(0ms));
}

TEST_CASE("WtsSensor: start_periodic_frames discards the frames queued before it") {
  test::MemoryStream s("scripted");
  WtsSensor sensor(s, grid_2x3());
  // Two frames of an earlier stream are queued while "tare" is awaited ...
  s.push(encode_frame(numbered_frame(1)));
  s.push(encode_frame(numbered_frame(2)));
  s.push(encode_reply(Reply{wts_id::kTare, 0, {}}));
  sensor.request_ok(encode_tare());
  // ... then the new stream starts: only its frames come out.
  s.push(encode_reply(Reply{wts_id::kStartPeriodicFrames, 0, {}}));
  s.push(encode_frame(numbered_frame(3)));
  sensor.start_periodic_frames(5.0);
  std::vector<std::uint32_t> read;
  while (const auto f = sensor.next_frame(0ms)) read.push_back(f->timestamp_ms);
  CHECK(read == std::vector<std::uint32_t>{3});
  CHECK(s.written.back() == encode_start_periodic_frames(200));
}

TEST_CASE("WtsSensor: a later matrix info with an unusable grid is refused, not hidden by the earlier grid") {
  test::MemoryStream s("scripted");
  WtsSensor sensor(s);
  s.push(encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(MatrixInfo{6, 14, 340, 340, 4095})}));
  CHECK(sensor.query_matrix_info().res_x == 6);
  REQUIRE(sensor.grid());
  CHECK(*sensor.grid() == Grid{14, 6});
  // The sensor now reports 0 columns: the parser keeps 14x6, the query says so.
  s.push(encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(MatrixInfo{0, 14, 340, 340, 4095})}));
  try {
    sensor.query_matrix_info();
    FAIL_CHECK("res_x=0 was accepted");
  } catch (const iclap::InvalidArgument& e) {
    CHECK(e.argument() == "matrix info");
    CHECK(std::string(e.what()).find("res_x=0, res_y=14") != std::string::npos);
  }
}

TEST_CASE("WtsSensor: at a loss every intact frame comes out, then DeviceLost, with the parser finished") {
  test::MemoryStream s("scripted");
  WtsSensor sensor(s, grid_2x3());
  s.push(encode_frame(numbered_frame(1)));
  s.push(encode_frame(numbered_frame(2)));
  const Bytes cut = encode_frame(numbered_frame(3));
  s.push(Bytes(cut.begin(), cut.begin() + 10));  // the unplug cuts frame 3
  s.gone = true;
  for (std::uint32_t t : {1u, 2u}) {
    CAPTURE(t);
    const auto f = sensor.next_frame(0ms);
    REQUIRE(f);
    CHECK(f->timestamp_ms == t);
  }
  CHECK_THROWS_AS(sensor.next_frame(0ms), DeviceLost);  // not "nothing yet"
  CHECK(sensor.lost());
  CHECK_FALSE(sensor.streaming());
  CHECK_THROWS_AS(sensor.next_frame(10ms), DeviceLost);
  // The cut frame was dropped when the parser was finished, not left waiting.
  const ParserStats st = sensor.stats();
  CHECK(sensor.parser().buffered() == 0);
  CHECK(st.truncated == 1);
  CHECK(st.junk_bytes == 10);
  CHECK(st.frames == 2);
  CHECK(st.bytes_in == st.packet_bytes + st.junk_bytes);
}

// --- Reproducer of a defect found by helper-40's audit (session 49), fixed in the same
// session. "Happens" is what the library did before the fix.

namespace {
// A sensor whose bytes arrive 50 ms into a read: a read that waits less gets
// nothing. Records the timeout of every read.
class LateStream final : public ByteStream {
 public:
  std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override {
    timeouts.push_back(timeout);
    if (timeout < 50ms) return 0;
    const std::size_t n = std::min(capacity, incoming.size() - at);
    std::copy_n(incoming.begin() + static_cast<std::ptrdiff_t>(at), n, buffer);
    at += n;
    return n;
  }
  void write(const std::uint8_t*, std::size_t, std::chrono::milliseconds) override {}
  void close() noexcept override {}
  bool is_open() const noexcept override { return true; }
  const std::string& name() const noexcept override { return name_; }
  Bytes incoming;
  std::size_t at = 0;
  std::vector<std::chrono::milliseconds> timeouts;

 private:
  std::string name_ = "late";
};
}  // namespace

TEST_CASE("WtsSensor: the longest timeout waits (next_frame and reply_timeout of milliseconds::max())") {
  // next_frame documents "waiting at most `timeout`", and
  // std::chrono::milliseconds::max() is the usual way to say "wait as long
  // as it takes". Expected: the read is given a long wait and the frame that
  // arrives 50 ms later is returned. Happens: steady_clock::now() + timeout
  // overflows (signed, undefined behaviour; UBSan reports it), the deadline
  // lies in the past, the stream is read once with a timeout of 0 and
  // next_frame returns nothing at once. Any timeout beyond about 292 years
  // minus the clock's epoch does the same.
  {
    LateStream s;
    s.incoming = encode_frame(numbered_frame(7));
    WtsSensor sensor(s, grid_2x3());
    const auto f = sensor.next_frame(std::chrono::milliseconds::max());
    REQUIRE_FALSE(s.timeouts.empty());
    CHECK(s.timeouts.front().count() >= 50);
    CHECK(f.has_value());
    if (f) CHECK(f->timestamp_ms == 7);
  }
  // Settings::reply_timeout = max: request() throws WtsTimeout "no reply to
  // 'get matrix info' after 3 attempt(s) of 9223372036854775807 ms" without
  // reading the stream once. Expected: the reply is read and returned.
  {
    LateStream s;
    s.incoming = encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(MatrixInfo{3, 2, 340, 340, 4095})});
    WtsSensor::Settings st;
    st.reply_timeout = std::chrono::milliseconds::max();
    WtsSensor sensor(s, st);
    MatrixInfo info;
    CHECK_NOTHROW(info = sensor.query_matrix_info());
    CHECK(info.grid() == Grid{2, 3});
    CHECK_FALSE(s.timeouts.empty());
  }
}
