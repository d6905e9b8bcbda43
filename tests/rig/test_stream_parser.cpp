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

TEST_CASE("Parser: a failed or short matrix info reply is passed on and sets no grid") {
  WtsStreamParser p;
  p.feed(encode_reply(Reply{wts_id::kGetMatrixInfo, 3, encode_matrix_info_payload(kWtsInfo)}));  // status 3
  p.feed(encode_reply(Reply{wts_id::kGetMatrixInfo, 0, Bytes{6, 0, 14, 0}}));                    // 4 bytes
  const auto got = drain(p);
  REQUIRE(got.size() == 2);
  CHECK(std::get<Reply>(got[0]).status == 3);
  CHECK(std::get<Reply>(got[0]).payload == encode_matrix_info_payload(kWtsInfo));
  CHECK(std::get<Reply>(got[1]).ok());
  CHECK(std::get<Reply>(got[1]).payload.size() == 4);
  CHECK_FALSE(p.grid());
  CHECK_FALSE(p.matrix_info());
  // The first successful, complete one sets it.
  p.feed(matrix_info_reply());
  REQUIRE(p.next());
  REQUIRE(p.grid());
  CHECK(*p.grid() == kWts);
  CHECK(p.stats().replies == 3);
  CHECK(p.stats().malformed == 0);
}

TEST_CASE("Parser: a later matrix info replaces the grid; one with an unusable grid does not") {
  WtsStreamParser p;
  p.feed(matrix_info_reply());
  p.feed(matrix_info_reply(MatrixInfo{8, 16, 340, 340, 4095}));  // the sensor, queried again, reports 16x8
  REQUIRE(drain(p).size() == 2);
  REQUIRE(p.grid());
  CHECK(*p.grid() == Grid{16, 8});
  CHECK(p.matrix_info()->res_x == 8);
  p.feed(matrix_info_reply(MatrixInfo{0, 14, 340, 340, 4095}));  // a side of 0: reported, not followed
  REQUIRE(p.next());
  CHECK(*p.grid() == Grid{16, 8});
  CHECK(p.matrix_info()->res_x == 0);
  Rng rng(5);
  p.feed(encode_frame(test::random_frame(rng, Grid{16, 8}, 1)));
  const auto m = p.next();
  REQUIRE(m);
  CHECK(std::get<TactileFrame>(*m).texels.rows() == 16);
  CHECK(std::get<TactileFrame>(*m).texels.cols() == 8);
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

// --- Framer: worst-case work, and feed() after finish() ---------------------

namespace {

// Junk of nested headers AA AA AA 01 <size> every 6 bytes, each announcing a
// packet that ends exactly at the end of the block (so every one is a
// complete candidate with a bad CRC inside all the earlier ones).
Bytes nested_header_junk(std::size_t length, std::size_t& headers) {
  Bytes b(length, 0x55);
  headers = 0;
  for (std::size_t p = 0; p + 8 <= length; p += 6, ++headers) {
    b[p] = b[p + 1] = b[p + 2] = 0xAA;
    b[p + 3] = 0x01;
    const std::size_t size = length - p - 8;
    b[p + 4] = static_cast<std::uint8_t>(size & 0xFF);
    b[p + 5] = static_cast<std::uint8_t>(size >> 8);
  }
  return b;
}

}  // namespace

TEST_CASE("Framer: junk of nested headers costs one CRC per preamble, whatever the chunking") {
  // Each header used to be CRC-checked again inside every candidate that
  // encloses it: (L/6)^2 / 2 CRCs of up to L bytes, O(L^3) (8 kB: seconds,
  // 64 kB: an hour). Now every position is checked once.
  const std::size_t length = 3000;
  std::size_t headers = 0;
  Bytes stream = nested_header_junk(length, headers);
  const Bytes good = encode_reply(Reply{wts_id::kTare, 0, {}});
  append(stream, good);
  for (std::size_t chunk : {stream.size(), std::size_t{1}, std::size_t{97}}) {
    CAPTURE(chunk);
    PacketFramer f(kWtsMaxPayload);
    std::vector<RawPacket> got;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      f.feed(stream.data() + at, std::min(chunk, stream.size() - at));
      while (auto p = f.next()) got.push_back(std::move(*p));
    }
    f.finish();
    while (auto p = f.next()) got.push_back(std::move(*p));
    REQUIRE(got.size() == 1);
    CHECK(got[0].id == wts_id::kTare);
    const auto& st = f.stats();
    CHECK(st.crc_errors == headers);
    CHECK(st.truncated == 0);
    CHECK(st.oversize == 0);
    CHECK(st.junk_bytes == length);
    CHECK(st.packet_bytes == good.size());
    // One CRC per header plus the good packet (the old code: over 100000).
    CHECK(f.crc_computations() <= headers + 1);
  }
}

TEST_CASE("Framer: a feed after finish() starts a new stream whether or not next() ran in between") {
  const Bytes pkt = encode_reply(Reply{wts_id::kLoop, 0, Bytes{1, 2, 3, 4}});
  const Bytes second = encode_reply(Reply{wts_id::kTare, 0, {}});
  struct Result {
    std::vector<std::uint8_t> ids;
    FramerStats stats;
  };
  // Feeds `first`, finish(), optionally drains, then feeds `then` and drains.
  const auto run = [](const Bytes& first, const Bytes& then, bool drain_between) {
    PacketFramer f;
    Result r;
    f.feed(first.data(), first.size());
    f.finish();
    if (drain_between)
      while (auto p = f.next()) r.ids.push_back(p->id);
    f.feed(then.data(), then.size());
    while (auto p = f.next()) r.ids.push_back(p->id);
    f.finish();
    while (auto p = f.next()) r.ids.push_back(p->id);
    r.stats = f.stats();
    return r;
  };
  SUBCASE("a packet cut by the end of a stream is not completed by the next one") {
    const Bytes head(pkt.begin(), pkt.begin() + 6), rest(pkt.begin() + 6, pkt.end());
    for (bool drain_between : {false, true}) {
      CAPTURE(drain_between);
      const Result r = run(head, rest, drain_between);
      CHECK(r.ids.empty());  // was the packet, spliced across the two streams
      CHECK(r.stats.truncated == 1);
      CHECK(r.stats.packets == 0);
      CHECK(r.stats.junk_bytes == pkt.size());
    }
  }
  SUBCASE("complete packets of the finished stream still come out, in order") {
    Bytes first = pkt;
    first.insert(first.end(), second.begin(), second.begin() + 5);  // cut short
    for (bool drain_between : {false, true}) {
      CAPTURE(drain_between);
      const Result r = run(first, second, drain_between);
      CHECK(r.ids == std::vector<std::uint8_t>{wts_id::kLoop, wts_id::kTare});
      CHECK(r.stats.packets == 2);
      CHECK(r.stats.oversize == 0);  // the cut header is not read across the streams
      CHECK(r.stats.junk_bytes == 5);
      CHECK(r.stats.bytes_in == r.stats.packet_bytes + r.stats.junk_bytes);
    }
  }
}

TEST_CASE("Framer: reset() drops the buffered bytes as junk, keeps the counters and the packets set aside") {
  const Bytes pkt = encode_reply(Reply{wts_id::kLoop, 0, Bytes{1, 2, 3, 4}});
  const Bytes other = encode_reply(Reply{wts_id::kTare, 0, {}});
  const Bytes head(pkt.begin(), pkt.begin() + 6), rest(pkt.begin() + 6, pkt.end());
  const auto balanced = [](const PacketFramer& f) {
    const FramerStats& s = f.stats();
    return s.bytes_in == s.packet_bytes + s.junk_bytes + f.buffered();
  };
  SUBCASE("a packet cut by the reset is not completed by what follows") {
    PacketFramer f;
    f.feed(other.data(), other.size());
    REQUIRE(f.next());
    f.feed(head.data(), head.size());
    CHECK_FALSE(f.next());
    CHECK(f.buffered() == head.size());
    f.reset();
    CHECK(f.buffered() == 0);
    CHECK(f.stats().bytes_in == other.size() + head.size());  // the counters stay
    CHECK(f.stats().packets == 1);
    CHECK(f.stats().junk_bytes == head.size());
    CHECK(balanced(f));
    f.feed(rest.data(), rest.size());
    f.feed(other.data(), other.size());
    f.finish();
    std::vector<std::uint8_t> ids;
    while (auto p = f.next()) ids.push_back(p->id);
    CHECK(ids == std::vector<std::uint8_t>{wts_id::kTare});  // not the loop packet spliced across the reset
    CHECK(f.stats().junk_bytes == head.size() + rest.size());
    CHECK(f.stats().truncated == 0);
    CHECK(balanced(f));
  }
  SUBCASE("packets a feed after finish() set aside still come out") {
    PacketFramer f;
    Bytes first = pkt;
    first.insert(first.end(), head.begin(), head.end());  // a second candidate, cut short
    f.feed(first.data(), first.size());
    f.finish();
    f.feed(head.data(), head.size());  // settles the finished stream: pkt set aside, its cut tail dropped
    f.reset();
    CHECK(f.buffered() == 0);
    const auto p = f.next();
    REQUIRE(p);
    CHECK(p->id == wts_id::kLoop);
    CHECK(p->payload == Bytes(pkt.begin() + 6, pkt.end() - 2));  // between the size field and the CRC
    CHECK_FALSE(f.next());
    CHECK(f.stats().packets == 1);
    CHECK(f.stats().junk_bytes == 2 * head.size());
    CHECK(balanced(f));
  }
}

TEST_CASE("Framer: an empty-payload packet ends a false header as soon as it is complete") {
  // A false header announcing 200 bytes, then a host command without payload
  // (8 bytes): the command comes out without waiting for 200 bytes or finish().
  Bytes stream{0xAA, 0xAA, 0xAA, 0x01, 0xC8, 0x00};
  const Bytes tare = encode_tare();
  append(stream, tare);
  for (std::size_t chunk : {stream.size(), std::size_t{1}}) {
    CAPTURE(chunk);
    PacketFramer f;
    std::vector<RawPacket> got;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      f.feed(stream.data() + at, std::min(chunk, stream.size() - at));
      while (auto p = f.next()) got.push_back(std::move(*p));
    }
    REQUIRE(got.size() == 1);
    CHECK(got[0].id == wts_id::kTare);
    CHECK(got[0].payload.empty());
    CHECK(f.buffered() == 0);
    CHECK(f.stats().truncated == 1);
    CHECK(f.stats().junk_bytes == 6);
  }
}

TEST_CASE("Framer: every candidate cut by the end of the stream counts as truncated") {
  // Two headers announcing 16 bytes each, the second inside the first; the
  // stream ends before either is complete.
  const Bytes stream{0xAA, 0xAA, 0xAA, 0x01, 0x10, 0x00, 1, 2, 3, 0xAA, 0xAA, 0xAA, 0x01, 0x10, 0x00, 4, 5};
  PacketFramer f;
  f.feed(stream.data(), stream.size());
  CHECK_FALSE(f.next());
  f.finish();
  CHECK_FALSE(f.next());
  CHECK(f.stats().truncated == 2);
  CHECK(f.stats().junk_bytes == stream.size());
  CHECK(f.buffered() == 0);
}

TEST_CASE("Framer: a raised payload bound judges the buffered bytes again") {
  // Under the bound 1024 a false header H1 (1000 bytes) encloses a reply P,
  // a false header H2 (1200) and a packet F of 1100 bytes; both H2 and F are
  // beyond the bound then. Once P is out the bound is raised to 1205 (as the
  // parser does for a grid from the matrix info): F now lies inside H2's
  // extent, so H2 is cut short and F comes out at once, as it would have in
  // a framer built with the raised bound.
  const Bytes h1{0xAA, 0xAA, 0xAA, 0x01, 0xE8, 0x03};
  const Bytes reply = encode_reply(Reply{wts_id::kTare, 0, {}});
  const Bytes h2{0xAA, 0xAA, 0xAA, 0x01, 0xB0, 0x04, 0x55, 0x55, 0x55, 0x55};
  const Bytes big = encode_loop(Bytes(1100, 0x11));
  Bytes stream = h1;
  append(stream, reply);
  append(stream, h2);
  append(stream, big);
  PacketFramer f;
  f.feed(stream.data(), stream.size());
  auto p = f.next();
  REQUIRE(p);
  CHECK(p->id == wts_id::kTare);
  f.set_max_payload(1205);
  p = f.next();
  REQUIRE(p);  // without finish()
  CHECK(p->id == wts_id::kLoop);
  CHECK(p->payload == Bytes(1100, 0x11));
  CHECK(f.buffered() == 0);
  const FramerStats& st = f.stats();
  CHECK(st.truncated == 2);
  CHECK(st.crc_errors == 0);
  CHECK(st.oversize == 0);
  CHECK(st.junk_bytes == h1.size() + h2.size());
  PacketFramer raised(1205);
  raised.feed(stream.data(), stream.size());
  std::size_t packets = 0;
  while (raised.next()) ++packets;
  CHECK(packets == 2);
  CHECK(raised.stats().truncated == st.truncated);
}

// --- Parser: grids larger than the payload bound ----------------------------

TEST_CASE("Parser: a grid whose frames exceed the payload bound raises the bound, so its frames decode") {
  const Grid big{20, 30};  // 600 taxels: 1205-byte frames, default bound 1024
  const MatrixInfo info{30, 20, 340, 340, 4095};
  REQUIRE(WtsStreamParser::frame_payload_size(big) == 1205);
  Rng rng(11);
  Bytes stream = matrix_info_reply(info);
  std::vector<TactileFrame> frames;
  for (std::uint32_t i = 0; i < 5; ++i) {
    frames.push_back(test::random_frame(rng, big, i));
    append(stream, encode_frame(frames.back()));
  }
  SUBCASE("from the matrix info, in any chunking") {
    for (std::size_t max_chunk : {std::size_t{1}, std::size_t{13}, stream.size()}) {
      CAPTURE(max_chunk);
      WtsStreamParser p;  // defaults, as `iclap record` uses
      CHECK(p.max_payload() == PacketFramer::kDefaultMaxPayload);
      const auto got = feed_chunked(p, stream, rng, max_chunk);
      REQUIRE(got.size() == 6);
      for (std::size_t k = 0; k < frames.size(); ++k) CHECK(same(got[k + 1], frames[k]));
      REQUIRE(p.grid());
      CHECK(*p.grid() == big);
      CHECK(p.max_payload() == 1205);
      const auto st = p.stats();
      CHECK(st.oversize == 0);
      CHECK(st.frames == 5);
      CHECK(st.junk_bytes == 0);
    }
  }
  SUBCASE("from an override, even below a small explicit bound") {
    WtsStreamParser::Settings s;
    s.grid = big;
    s.max_payload = 16;
    WtsStreamParser p(s);
    CHECK(p.max_payload() == 1205);
    p.feed(encode_frame(frames[0]));
    auto m = p.next();
    REQUIRE(m);
    CHECK(same(*m, frames[0]));
    WtsStreamParser q;
    q.set_grid(big);
    CHECK(q.max_payload() == 1205);
    q.set_grid(kWts);  // never lowered
    CHECK(q.max_payload() == 1205);
  }
  SUBCASE("a feed after finish() decodes the finished stream with the grid it learnt") {
    for (bool drain_between : {false, true}) {
      CAPTURE(drain_between);
      WtsStreamParser p;
      p.feed(stream);
      p.finish();
      std::vector<WtsMessage> got;
      if (drain_between) got = drain(p);
      p.feed(encode_frame(frames[0]));
      for (auto& m : drain(p)) got.push_back(std::move(m));
      CHECK(got.size() == 7);
      CHECK(p.stats().frames == 6);
    }
  }
  SUBCASE("a grid no WTS frame can carry is refused") {
    CHECK(WtsStreamParser::kMaxGridTaxels == 32765);
    WtsStreamParser p;
    CHECK_THROWS_AS(p.set_grid(Grid{1, 32766}), iclap::InvalidArgument);
    CHECK_NOTHROW(p.set_grid(Grid{1, 32765}));
    CHECK(p.max_payload() == kWtsMaxPayload);
    // Sides whose product overflows (to 4 and to 0) were taken as small.
    CHECK_THROWS_AS(p.set_grid(Grid{4, (iclap::Index{1} << 62) + 1}), iclap::InvalidArgument);
    CHECK_THROWS_AS(p.set_grid(Grid{iclap::Index{1} << 32, iclap::Index{1} << 32}), iclap::InvalidArgument);
    CHECK_THROWS_AS(p.set_grid(Grid{32765, 32765}), iclap::InvalidArgument);
    CHECK_NOTHROW(p.set_grid(Grid{5, 6553}));
    WtsStreamParser q;
    q.feed(matrix_info_reply(MatrixInfo{200, 200, 340, 340, 4095}));  // 40000 taxels
    REQUIRE(q.next());
    CHECK(q.matrix_info());
    CHECK_FALSE(q.grid());
    CHECK(q.max_payload() == PacketFramer::kDefaultMaxPayload);
  }
}
