#!/usr/bin/env bash
# The whole test suite, as CI runs it: installs any missing Debian package,
# then builds and runs every test twice, in Release with g++ (warnings as
# errors) and with clang++ under AddressSanitizer + UndefinedBehaviorSanitizer
# (warnings as errors too), then the fuzzers.
#
# The sanitizer half uses clang++ at -O1 -g1 because, from an empty ccache,
# it is the slowest part of CI: tests/recognition/test_recognition.cpp
# compiled in 88 s with clang++ against 120 s with g++ (both -O1 -g1, side by
# side), and with g++ -g1 took 27% off -g on another test file. Line tables
# still give FILE:LINE in sanitizer reports. ICLAP_SANITIZE_CXX picks another
# compiler. The half also puts every test through a second compiler.
set -euo pipefail
cd "$(dirname "$0")/.."
source .ci/deps.sh
iclap_install_deps clang libclang-rt-14-dev
jobs="${ICLAP_JOBS:-2}"
launcher="$(iclap_cmake_launcher_args)"

echo "== Release build and tests" >&2
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DICLAP_WERROR=ON $launcher >/dev/null
cmake --build build/release -j "$jobs"
ctest --test-dir build/release --output-on-failure -j "$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests" >&2
cmake -S . -B build/asan-clang -DCMAKE_CXX_COMPILER="${ICLAP_SANITIZE_CXX:-clang++}" \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DICLAP_SANITIZE=address,undefined \
  -DICLAP_WERROR=ON -DICLAP_BUILD_BENCHMARKS=OFF $launcher >/dev/null
cmake --build build/asan-clang -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan-clang --output-on-failure -j "$jobs"

if [ -f tests/fuzz/run.sh ]; then
  echo "== Fuzzers" >&2
  bash tests/fuzz/run.sh
fi
echo "== All tests passed" >&2
