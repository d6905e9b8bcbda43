// SPDX-License-Identifier: MIT
// libFuzzer target: the dataset CSV reader. Built and run by tests/fuzz/run.sh.
#include "fuzz_dataset_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  iclap::fuzz::fuzz_dataset_csv(data, size);
  return 0;
}
