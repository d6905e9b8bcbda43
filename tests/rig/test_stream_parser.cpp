// SPDX-License-Identifier: MIT
// The WTS stream parser: decoding, grid, resynchronisation, bounds, and
// property tests over random chunking, junk, truncation and bit flips.

#include <doctest/doctest.h>

#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/rig/stream_parser.hpp"
#include "rig_test_util.hpp"

using namespace iclap::rig;
using iclap::Rng;
using test::encode;
using test::same;

namespace {

const Grid kWts{14, 6};
const MatrixInfo kWtsInfo{6, 14, 340, 340, 4095};

Bytes matrix_info_reply(const MatrixInfo& info = kWtsInfo) {
  return encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(info)});
}

std::vector<WtsMessage> drain(WtsStreamParser& p) {
  std::vector<WtsMessage> out;
  while (auto m = p.next()) out.push_back(std::move(*m));
  return out;
}

std::vector<WtsMessage> parse_all(const Bytes& bytes, WtsStreamParser::Settings s = {}) {
  WtsStreamParser p(s);
  p.feed(bytes);
  auto out = drain(p);
  p.finish();
  for (auto& m : drain(p)) out.push_back(std::move(m));
  return out;
}

void append(Bytes& to, const Bytes& from) { to.insert(to.end(), from.begin(), from.end()); }

void check_same_stats(const ParserStats& a, const ParserStats& b) {
  CHECK(a.bytes_in == b.bytes_in);
  CHECK(a.packets == b.packets);
  CHECK(a.packet_bytes == b.packet_bytes);
  CHECK(a.junk_bytes == b.junk_bytes);
  CHECK(a.crc_errors == b.crc_errors);
  CHECK(a.oversize == b.oversize);
  CHECK(a.truncated == b.truncated);
  CHECK(a.frames == b.frames);
  CHECK(a.replies == b.replies);
  CHECK(a.frames_wrong_shape == b.frames_wrong_shape);
  CHECK(a.frames_without_grid == b.frames_without_grid);
  CHECK(a.frames_out_of_range == b.frames_out_of_range);
  CHECK(a.malformed == b.malformed);
}

// Feeds `bytes` in random chunks of 1..max_chunk, collecting messages.
std::vector<WtsMessage> feed_chunked(WtsStreamParser& p, const Bytes& bytes, Rng& rng, std::size_t max_chunk) {
  std::vector<WtsMessage> out;
  for (std::size_t at = 0; at < bytes.size();) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - at, 1 + rng.below(max_chunk));
    p.feed(bytes.data() + at, n);
    at += n;
    for (auto& m : drain(p)) out.push_back(std::move(m));
  }
  p.finish();
  for (auto& m : drain(p)) out.push_back(std::move(m));
  return out;
}

}  // namespace

TEST_CASE("Parser: matrix info sets the grid, frames decode row-major") {
  WtsStreamParser p;
  CHECK_FALSE(p.grid());
  p.feed(matrix_info_reply());
  auto m = p.next();
  REQUIRE(m);
  const auto& reply = std::get<Reply>(*m);
  CHECK(reply.id == wts_id::kGetMatrixInfo);
  CHECK(reply.ok());
  REQUIRE(p.grid());
  CHECK(*p.grid() == kWts);  // rows = res_y = 14, cols = res_x = 6
  REQUIRE(p.matrix_info());
  CHECK(p.matrix_info()->cell_width == 340);

  TactileFrame f;
  f.timestamp_ms = 123456;
  f.flags = 2;
  f.texels.resize(14, 6);
  for (int r = 0; r < 14; ++r)
    for (int c = 0; c < 6; ++c) f.texels(r, c) = static_cast<std::uint16_t>(100 * r + c);
  p.feed(encode_frame(f));
  m = p.next();
  REQUIRE(m);
  const auto& got = std::get<TactileFrame>(*m);
  CHECK(got.timestamp_ms == 123456);
  CHECK(got.flags == 2);
  REQUIRE(got.texels.rows() == 14);
  REQUIRE(got.texels.cols() == 6);
  CHECK(got.texels(13, 5) == 1305);
  CHECK(got.texels(1, 0) == 100);
  CHECK(got.pressures()(13, 5) == 1305.0);
  CHECK_FALSE(p.next());
  const auto s = p.stats();
  CHECK(s.frames == 1);
  CHECK(s.replies == 1);
  CHECK(s.junk_bytes == 0);
  CHECK(s.bytes_in == s.packet_bytes);
}

TEST_CASE("Parser: a grid override is kept over the matrix info") {
  WtsStreamParser::Settings s;
  s.grid = Grid{6, 14};
  WtsStreamParser p(s);
  p.feed(matrix_info_reply());
  REQUIRE(p.next());
  CHECK(*p.grid() == Grid{6, 14});
  CHECK(p.grid_overridden());
  Rng rng(1);
  p.feed(encode_frame(test::random_frame(rng, Grid{6, 14}, 1)));
  auto m = p.next();
  REQUIRE(m);
  CHECK(std::get<TactileFrame>(*m).texels.rows() == 6);
  CHECK_THROWS_AS(p.set_grid(Grid{0, 3}), iclap::InvalidArgument);
  CHECK_THROWS_AS(WtsStreamParser(WtsStreamParser::Settings{1024, Grid{-1, 3}, 4095}), iclap::InvalidArgument);
}

TEST_CASE("Parser: frames of the wrong shape, before a grid, out of range or malformed are dropped and counted") {
  Rng rng(2);
  WtsStreamParser p;
  p.feed(encode_frame(test::random_frame(rng, kWts, 1)));  // no grid yet
  CHECK_FALSE(p.next());
  CHECK(p.stats().frames_without_grid == 1);

  p.set_grid(kWts);
  p.feed(encode_frame(test::random_frame(rng, Grid{10, 10}, 2)));
  CHECK_FALSE(p.next());
  CHECK(p.stats().frames_wrong_shape == 1);
  CHECK(p.stats().last_wrong_shape_taxels == 100);
  // Same count, other shape: accepted and shaped by the grid (the wire
  // cannot tell them apart; that is what the override is for).
  p.feed(encode_frame(test::random_frame(rng, Grid{6, 14}, 3)));
  auto m = p.next();
  REQUIRE(m);
  CHECK(std::get<TactileFrame>(*m).texels.rows() == 14);

  TactileFrame hot = test::random_frame(rng, kWts, 4);
  hot.texels(3, 3) = 4096;
  p.feed(encode_frame(hot));
  CHECK_FALSE(p.next());
  CHECK(p.stats().frames_out_of_range == 1);

  p.feed(encode_packet(wts_id::kFrameData, Bytes{1, 2, 3, 4}));      // too short
  p.feed(encode_packet(wts_id::kFrameData, Bytes{1, 2, 3, 4, 5, 6}));  // odd taxel bytes
  p.feed(encode_packet(wts_id::kTare, Bytes{0}));                      // reply without status
  CHECK_FALSE(p.next());
  CHECK(p.stats().malformed == 3);
  CHECK(p.stats().frames == 1);
  CHECK(p.stats().packets == 7);
  CHECK(p.stats().junk_bytes == 0);

  WtsStreamParser::Settings loose;
  loose.grid = kWts;
  loose.max_texel = 0xFFFF;
  WtsStreamParser q(loose);
  q.feed(encode_frame(hot));
  m = q.next();
  REQUIRE(m);
  CHECK(std::get<TactileFrame>(*m).texels(3, 3) == 4096);
}

TEST_CASE("Parser: junk, bad CRC and oversize headers resynchronise") {
  Rng rng(3);
  WtsStreamParser::Settings s;
  s.grid = kWts;
  s.max_payload = 200;
  WtsStreamParser p(s);
  Bytes stream{0x00, 0x13, 0xAA, 0xAA, 0x55};             // junk
  append(stream, {0xAA, 0xAA, 0xAA, 0x00, 0x2C, 0x01});  // header announcing 300 > 200
  Bytes bad = encode_frame(test::random_frame(rng, kWts, 7));
  bad[20] ^= 0x10;  // CRC error
  append(stream, bad);
  const TactileFrame good = test::random_frame(rng, kWts, 8);
  append(stream, encode_frame(good));
  append(stream, {0xAA, 0xAA});  // trailing partial preamble
  p.feed(stream);
  auto out = drain(p);
  REQUIRE(out.size() == 1);
  CHECK(same(out[0], good));
  auto st = p.stats();
  CHECK(st.oversize == 1);
  CHECK(st.crc_errors >= 1);
  CHECK(p.buffered() == 2);
  p.finish();
  CHECK(drain(p).empty());
  st = p.stats();
  CHECK(p.buffered() == 0);
  CHECK(st.bytes_in == st.packet_bytes + st.junk_bytes);
  CHECK(st.junk_bytes == stream.size() - encode_frame(good).size());
  CHECK_THROWS_AS(PacketFramer(65536), iclap::InvalidArgument);
}

TEST_CASE("Parser: a corrupted size field does not hold back later packets") {
  // With the largest bound, a false header announcing 60000 bytes must not
  // make the parser wait for 60 kB: the next valid packet comes out as soon
  // as it is complete, without finish().
  Rng rng(4);
  WtsStreamParser::Settings s;
  s.grid = kWts;
  s.max_payload = 65535;
  WtsStreamParser p(s);
  p.feed(Bytes{0xAA, 0xAA, 0xAA, 0x00, 0x60, 0xEA, 0x01, 0x02});
  CHECK_FALSE(p.next());
  const TactileFrame f = test::random_frame(rng, kWts, 9);
  const Bytes packet = encode_frame(f);
  p.feed(packet.data(), packet.size() - 1);
  CHECK_FALSE(p.next());  // not complete yet
  p.feed(&packet.back(), 1);
  auto m = p.next();
  REQUIRE(m);
  CHECK(same(*m, f));
  CHECK(p.stats().truncated == 1);
  CHECK(p.stats().junk_bytes == 8);
}

TEST_CASE("Parser: a packet nested in a valid packet's payload wins (chunking-independent rule)") {
  // Documented trade-off: a candidate inside which a complete valid packet
  // starts is dropped, so the result does not depend on chunking. A loop
  // echo that carries a whole packet therefore yields the inner packet.
  const Bytes inner = encode_reply(Reply{wts_id::kTare, 0, {}});
  const Bytes outer = encode_loop(Bytes(inner.begin(), inner.end()));
  for (std::size_t chunk : {std::size_t{1}, outer.size()}) {
    WtsStreamParser p;
    Rng rng(6);
    const auto got = feed_chunked(p, outer, rng, chunk);
    REQUIRE(got.size() == 1);
    CHECK(std::get<Reply>(got[0]).id == wts_id::kTare);
    CHECK(p.stats().truncated == 1);
  }
}

TEST_CASE("Parser: finish() drops an incomplete tail and a later feed starts afresh") {
  Rng rng(5);
  WtsStreamParser p(WtsStreamParser::Settings{1024, kWts, 4095});
  const Bytes packet = encode_frame(test::random_frame(rng, kWts, 1));
  p.feed(packet.data(), 50);
  CHECK_FALSE(p.next());
  p.finish();
  CHECK_FALSE(p.next());
  CHECK(p.buffered() == 0);
  CHECK(p.stats().truncated == 1);
  CHECK(p.stats().junk_bytes == 50);
  p.feed(packet);
  CHECK(p.next());
}

TEST_CASE("Parser property: any chunking gives the same messages") {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    CAPTURE(seed);
    Rng rng = Rng::derive(2024, 1, seed);
    Bytes stream = matrix_info_reply();
    std::vector<WtsMessage> expected{Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload(kWtsInfo)}};
    for (int i = 0; i < 30; ++i) {
      WtsMessage m = rng.below(4) == 0 ? WtsMessage(test::random_reply(rng))
                                       : WtsMessage(test::random_frame(rng, kWts, static_cast<std::uint32_t>(i)));
      append(stream, encode(m));
      expected.push_back(std::move(m));
    }
    const auto whole = parse_all(stream);
    REQUIRE(whole.size() == expected.size());
    for (std::size_t k = 0; k < whole.size(); ++k) CHECK(same(whole[k], expected[k]));
    for (std::size_t max_chunk : {std::size_t{1}, std::size_t{7}, std::size_t{64}, stream.size()}) {
      CAPTURE(max_chunk);
      WtsStreamParser p;
      const auto got = feed_chunked(p, stream, rng, max_chunk);
      REQUIRE(got.size() == expected.size());
      for (std::size_t k = 0; k < got.size(); ++k) CHECK(same(got[k], expected[k]));
      const auto st = p.stats();
      CHECK(st.junk_bytes == 0);
      CHECK(st.bytes_in == st.packet_bytes);
    }
  }
}

TEST_CASE("Parser property: junk, truncated packets and single-bit flips lose only the damaged packets") {
  std::uint64_t total_damaged = 0, total_intact = 0;
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    CAPTURE(seed);
    Rng rng = Rng::derive(77, 2, seed);
    const Grid grid{static_cast<iclap::Index>(1 + rng.below(16)), static_cast<iclap::Index>(1 + rng.below(8))};
    CAPTURE(to_string(grid));
    Bytes stream;
    std::vector<WtsMessage> expected;
    std::size_t damaged = 0;
    for (int i = 0; i < 40; ++i) {
      const auto kind = rng.below(10);
      if (kind == 0) {
        append(stream, test::random_junk(rng, 40));
      }
      WtsMessage m = rng.below(5) == 0 ? WtsMessage(test::random_reply(rng))
                                       : WtsMessage(test::random_frame(rng, grid, static_cast<std::uint32_t>(i)));
      Bytes packet = encode(m);
      if (kind == 1) {  // truncated: a proper prefix of the packet
        packet.resize(1 + rng.below(packet.size() - 1));
        ++damaged;
      } else if (kind == 2) {  // one flipped bit anywhere
        packet[rng.below(packet.size())] ^= static_cast<std::uint8_t>(1u << rng.below(8));
        ++damaged;
      } else {
        expected.push_back(std::move(m));
      }
      append(stream, packet);
    }
    if (rng.below(2) == 0) append(stream, test::random_junk(rng, 40));
    WtsStreamParser::Settings s;
    s.grid = grid;
    WtsStreamParser p(s);
    const auto got = feed_chunked(p, stream, rng, 1 + rng.below(100));
    WtsStreamParser whole(s);
    whole.feed(stream);
    whole.finish();
    std::size_t whole_count = 0;
    while (whole.next()) ++whole_count;
    CHECK(whole_count == got.size());
    check_same_stats(whole.stats(), p.stats());  // decisions never depend on chunking
    REQUIRE(got.size() == expected.size());
    for (std::size_t k = 0; k < got.size(); ++k) CHECK(same(got[k], expected[k]));
    const auto st = p.stats();
    CHECK(p.buffered() == 0);
    CHECK(st.bytes_in == stream.size());
    CHECK(st.bytes_in == st.packet_bytes + st.junk_bytes);
    CHECK(st.packets == expected.size());
    total_damaged += damaged;
    total_intact += expected.size();
  }
  CHECK(total_damaged > 300);  // the property was exercised
  CHECK(total_intact > 1500);
}
