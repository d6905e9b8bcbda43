// SPDX-License-Identifier: MIT
#pragma once
// Fuzz entry for the WTS stream parser, shared by the libFuzzer target
// (fuzz_stream_parser.cpp, built by tests/fuzz/run.sh) and the doctest
// suite (test_fuzz_corpus.cpp runs it on the seed corpus).
//
// Input: byte 0 picks the settings (grid, payload bound, taxel bound),
// byte 1 seeds the chunking, the rest is the stream. Invariants checked
// (std::logic_error on violation, which libFuzzer reports as a crash):
// - feeding at once and in random chunks gives the same messages and the
//   same counters (decisions depend only on the bytes);
// - every byte is accounted for: bytes = packet bytes + junk bytes, and
//   every valid packet is a yielded message or a counted drop;
// - every frame has the grid's shape and taxels within the bound;
// - every message re-encodes to bytes found verbatim in the input.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/rig/stream_parser.hpp"

namespace iclap::fuzz {

inline void fuzz_require(bool ok, const char* what) {
  if (!ok) throw std::logic_error(std::string("stream parser invariant violated: ") + what);
}

inline void fuzz_stream_parser(const std::uint8_t* data, std::size_t size) {
  using namespace iclap::rig;
  if (size < 2) return;
  const std::uint8_t config = data[0];
  const std::uint8_t chunk_seed = data[1];
  data += 2;
  size -= 2;

  WtsStreamParser::Settings s;
  static const Grid grids[] = {{0, 0}, {14, 6}, {2, 3}, {1, 1}};
  const Grid g = grids[config & 3];
  if (g.rows > 0) s.grid = g;
  static const std::size_t bounds[] = {1024, 200, 16, 65535};
  s.max_payload = bounds[(config >> 2) & 3];
  s.max_texel = (config & 16) ? 0xFFFF : 4095;

  // The parser raises its payload bound to carry the frames of a grid it
  // learns (never lowers it): packets are bounded by the largest it had.
  std::size_t bound = s.max_payload;
  const auto run = [&](std::size_t max_chunk, std::vector<WtsMessage>& out) {
    WtsStreamParser p(s);
    Rng rng(chunk_seed);
    for (std::size_t at = 0; at < size;) {
      const std::size_t n = max_chunk ? std::min<std::size_t>(size - at, 1 + rng.below(max_chunk)) : size;
      p.feed(data + at, n);
      at += n;
      while (auto m = p.next()) out.push_back(std::move(*m));
    }
    p.finish();
    while (auto m = p.next()) out.push_back(std::move(*m));
    fuzz_require(p.buffered() == 0, "bytes left after finish()");
    fuzz_require(p.max_payload() >= s.max_payload, "the payload bound was lowered");
    bound = std::max(bound, p.max_payload());
    return p.stats();
  };
  std::vector<WtsMessage> whole, chunked;
  const ParserStats a = run(0, whole);
  const ParserStats b = run(1 + (chunk_seed % 64u), chunked);

  fuzz_require(whole.size() == chunked.size(), "chunking changed the number of messages");
  fuzz_require(a.bytes_in == size, "bytes_in");
  fuzz_require(a.packet_bytes + a.junk_bytes == size, "bytes = packet bytes + junk bytes");
  fuzz_require(a.frames + a.replies + a.malformed + a.frames_wrong_shape + a.frames_without_grid +
                       a.frames_out_of_range ==
                   a.packets,
               "every packet yielded or counted");
  fuzz_require(a.frames + a.replies == whole.size(), "message count");
  const std::uint64_t fa[] = {a.packets, a.packet_bytes, a.junk_bytes, a.crc_errors, a.oversize, a.truncated,
                              a.frames, a.replies, a.malformed, a.frames_wrong_shape, a.frames_without_grid,
                              a.frames_out_of_range};
  const std::uint64_t fb[] = {b.packets, b.packet_bytes, b.junk_bytes, b.crc_errors, b.oversize, b.truncated,
                              b.frames, b.replies, b.malformed, b.frames_wrong_shape, b.frames_without_grid,
                              b.frames_out_of_range};
  fuzz_require(std::equal(std::begin(fa), std::end(fa), std::begin(fb)), "chunking changed the counters");

  for (std::size_t i = 0; i < whole.size(); ++i) {
    const WtsMessage& m = whole[i];
    fuzz_require(m.index() == chunked[i].index(), "chunking changed a message kind");
    Bytes encoded;
    if (const auto* f = std::get_if<TactileFrame>(&m)) {
      const auto& f2 = std::get<TactileFrame>(chunked[i]);
      fuzz_require(f->texels.rows() >= 1 && f->texels.cols() >= 1, "empty frame");
      fuzz_require(f->texels.rows() == f2.texels.rows() && f->texels.cols() == f2.texels.cols() &&
                       f->texels == f2.texels && f->timestamp_ms == f2.timestamp_ms,
                   "chunking changed a frame");
      if (s.grid) fuzz_require(f->texels.rows() == s.grid->rows && f->texels.cols() == s.grid->cols, "frame shape");
      fuzz_require(f->texels.maxCoeff() <= s.max_texel, "taxel above the bound");
      encoded = encode_frame(*f);
    } else {
      const auto& r = std::get<Reply>(m);
      const auto& r2 = std::get<Reply>(chunked[i]);
      fuzz_require(r.id == r2.id && r.status == r2.status && r.payload == r2.payload, "chunking changed a reply");
      fuzz_require(r.id != wts_id::kFrameData, "a reply with the frame id");
      encoded = encode_reply(r);
    }
    fuzz_require(encoded.size() <= kWtsHeaderSize + bound + kWtsCrcSize, "packet above the bound");
    fuzz_require(std::search(data, data + size, encoded.begin(), encoded.end()) != data + size,
                 "a message that is not in the input");
  }
}

}  // namespace iclap::fuzz
