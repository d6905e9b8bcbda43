// SPDX-License-Identifier: MIT
// libFuzzer target: the WTS stream parser. Built and run by tests/fuzz/run.sh.
#include "fuzz_stream_parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  iclap::fuzz::fuzz_stream_parser(data, size);
  return 0;
}
