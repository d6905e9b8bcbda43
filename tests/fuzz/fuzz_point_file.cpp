// SPDX-License-Identifier: MIT
// libFuzzer target: the point-file reader of `iclap register`. Built and run
// by tests/fuzz/run.sh.
#include "fuzz_heap.hpp"
#include "fuzz_point_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const iclap::fuzz::FuzzHeapWatch heap;
  iclap::fuzz::fuzz_point_file(data, size);
  heap.check(size);
  return 0;
}
