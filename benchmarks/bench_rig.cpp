// SPDX-License-Identifier: MIT
// WTS stream parser throughput. The rig needs 5 frames/s x 173 bytes; the
// point is headroom and the cost of resynchronisation. Baseline in the same
// run: the bare CRC over the same bytes (work the parser cannot avoid), so
// the ratio parser/CRC is the framing + decoding overhead.
//
//   build/release/benchmarks/bench_rig --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/rig/stream_parser.hpp"

namespace {

using namespace iclap::rig;

// 2000 WTS frames (14x6); with `damage`, junk before every 3rd frame and a
// flipped bit in every 5th.
Bytes make_stream(bool damage) {
  iclap::Rng rng(42);
  Bytes out = encode_reply(Reply{wts_id::kGetMatrixInfo, 0, encode_matrix_info_payload({6, 14, 340, 340, 4095})});
  for (std::uint32_t i = 0; i < 2000; ++i) {
    TactileFrame f;
    f.timestamp_ms = 200 * i;
    f.texels.resize(14, 6);
    for (iclap::Index k = 0; k < f.texels.size(); ++k) f.texels.data()[k] = static_cast<std::uint16_t>(rng.below(4096));
    Bytes p = encode_frame(f);
    if (damage && i % 3 == 0)
      for (std::uint64_t j = rng.below(40); j > 0; --j)
        out.push_back(rng.below(3) == 0 ? 0xAA : static_cast<std::uint8_t>(rng.below(256)));
    if (damage && i % 5 == 0) p[6 + rng.below(p.size() - 6)] ^= static_cast<std::uint8_t>(1u << rng.below(8));
    out.insert(out.end(), p.begin(), p.end());
  }
  return out;
}

void BM_CrcBaseline(benchmark::State& state) {
  const Bytes stream = make_stream(state.range(0) != 0);
  for (auto _ : state) benchmark::DoNotOptimize(wts_crc16(stream.data(), stream.size()));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(stream.size()));
}
BENCHMARK(BM_CrcBaseline)->ArgNames({"damage"})->Arg(0)->Arg(1);

void BM_Parser(benchmark::State& state) {
  const Bytes stream = make_stream(state.range(0) != 0);
  const auto chunk = static_cast<std::size_t>(state.range(1));
  std::uint64_t frames = 0;
  for (auto _ : state) {
    WtsStreamParser p;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      p.feed(stream.data() + at, std::min(chunk, stream.size() - at));
      while (auto m = p.next()) frames += std::holds_alternative<TactileFrame>(*m);
    }
    p.finish();
    while (auto m = p.next()) frames += std::holds_alternative<TactileFrame>(*m);
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(stream.size()));
  state.counters["frames_per_pass"] = static_cast<double>(frames) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_Parser)->ArgNames({"damage", "chunk"})->ArgsProduct({{0, 1}, {1, 64, 4096}});

}  // namespace

BENCHMARK_MAIN();
