// SPDX-License-Identifier: MIT
#pragma once
// Small helpers shared by the rig tests: hex dumps, random frames and
// replies (through iclap::Rng, fixed seeds), message comparison, an
// in-memory byte stream, a one-frame dataset for the recorder's cases.

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/rig/byte_stream.hpp"
#include "iclap/rig/wts_message.hpp"

namespace iclap::rig::test {

/// A sensor's side of the wire, in memory: `incoming` is handed out as it is
/// read (everything at once, no waiting), every write is kept; counts reads
/// and writes. With `gone`, writes throw DeviceLost, and so does a read once
/// `incoming` is used up (an unplug after the bytes that reached the host).
class MemoryStream final : public ByteStream {
 public:
  explicit MemoryStream(std::string name = "memory") : name_(std::move(name)) {}
  std::size_t read(std::uint8_t* buffer, std::size_t capacity, std::chrono::milliseconds) override {
    ++reads;
    if (gone && at == incoming.size()) throw DeviceLost(name_, "device gone");
    const std::size_t n = std::min(capacity, incoming.size() - at);
    std::copy_n(incoming.begin() + static_cast<std::ptrdiff_t>(at), n, buffer);
    at += n;
    return n;
  }
  void write(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds) override {
    ++write_calls;
    if (gone) throw DeviceLost(name_, "device gone");
    written.emplace_back(data, data + size);
  }
  void close() noexcept override {}
  bool is_open() const noexcept override { return true; }
  const std::string& name() const noexcept override { return name_; }
  void push(const Bytes& b) { incoming.insert(incoming.end(), b.begin(), b.end()); }

  Bytes incoming;
  std::size_t at = 0;
  std::size_t reads = 0;
  std::vector<Bytes> written;
  std::size_t write_calls = 0;
  bool gone = false;

 private:
  std::string name_;
};

/// "aa aa 30" for {0xAA, 0xAA, 0x30}.
inline std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char buf[4];
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02x", bytes[i]);
    if (i) out += ' ';
    out += buf;
  }
  return out;
}

/// A 2x3 frame whose taxels all read `value`.
inline TactileFrame flat_frame(std::uint32_t timestamp_ms, std::uint16_t value) {
  TactileFrame f;
  f.timestamp_ms = timestamp_ms;
  f.texels = TexelImage::Constant(2, 3, value);
  return f;
}

/// A frame with random 12-bit taxels.
inline TactileFrame random_frame(Rng& rng, const Grid& grid, std::uint32_t timestamp_ms) {
  TactileFrame f;
  f.timestamp_ms = timestamp_ms;
  f.flags = static_cast<std::uint8_t>(rng.below(256));
  f.texels.resize(grid.rows, grid.cols);
  for (Index i = 0; i < f.texels.size(); ++i) f.texels.data()[i] = static_cast<std::uint16_t>(rng.below(4096));
  return f;
}

/// A reply with a random id (not 0x00, not get matrix info), status and payload.
inline Reply random_reply(Rng& rng) {
  Reply r;
  do {
    r.id = static_cast<std::uint8_t>(1 + rng.below(255));
  } while (r.id == wts_id::kGetMatrixInfo);
  r.status = rng.below(4) == 0 ? static_cast<std::uint16_t>(rng.below(65536)) : 0;
  r.payload.resize(rng.below(24));
  for (auto& b : r.payload) b = static_cast<std::uint8_t>(rng.below(256));
  return r;
}

/// Junk bytes, a third of them 0xAA so false preambles are common.
inline Bytes random_junk(Rng& rng, std::size_t max_size) {
  Bytes junk(rng.below(max_size + 1));
  for (auto& b : junk) b = rng.below(3) == 0 ? 0xAA : static_cast<std::uint8_t>(rng.below(256));
  return junk;
}

inline bool same(const WtsMessage& a, const WtsMessage& b) {
  if (a.index() != b.index()) return false;
  if (const auto* fa = std::get_if<TactileFrame>(&a)) {
    const auto& fb = std::get<TactileFrame>(b);
    return fa->timestamp_ms == fb.timestamp_ms && fa->flags == fb.flags && fa->texels.rows() == fb.texels.rows() &&
           fa->texels.cols() == fb.texels.cols() && fa->texels == fb.texels;
  }
  const auto& ra = std::get<Reply>(a);
  const auto& rb = std::get<Reply>(b);
  return ra.id == rb.id && ra.status == rb.status && ra.payload == rb.payload;
}

inline Bytes encode(const WtsMessage& m) {
  if (const auto* f = std::get_if<TactileFrame>(&m)) return encode_frame(*f);
  return encode_reply(std::get<Reply>(m));
}

/// A dataset of one all-zero 14 x 6 frame of mug, exploration 2, at time 1
/// s (what `iclap record --object mug --exploration 2` appends to).
inline Dataset one_mug_frame(std::int64_t frame) {
  Dataset one;
  one.rows = 14;
  one.cols = 6;
  Frame f;
  f.object = "mug";
  f.exploration = 2;
  f.frame = frame;
  f.time = 1.0;
  f.pressures = Eigen::MatrixXd::Zero(14, 6);
  one.frames.push_back(f);
  return one;
}

}  // namespace iclap::rig::test
