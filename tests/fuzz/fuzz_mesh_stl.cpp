// SPDX-License-Identifier: MIT
// libFuzzer target: the STL mesh loader. Built and run by tests/fuzz/run.sh.
#include "fuzz_heap.hpp"
#include "fuzz_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const iclap::fuzz::FuzzHeapWatch heap;
  iclap::fuzz::fuzz_mesh_stl(data, size);
  heap.check(size);
  return 0;
}
