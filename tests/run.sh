#!/usr/bin/env bash
# The whole test suite, as CI runs it: installs any missing Debian package,
# then builds and runs every test twice, in Release (warnings as errors) and
# under AddressSanitizer + UndefinedBehaviorSanitizer, then the fuzzers.
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
cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DICLAP_SANITIZE=address,undefined -DICLAP_WERROR=ON -DICLAP_BUILD_BENCHMARKS=OFF $launcher >/dev/null
cmake --build build/asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs"

if [ -f tests/fuzz/run.sh ]; then
  echo "== Fuzzers" >&2
  bash tests/fuzz/run.sh
fi
echo "== All tests passed" >&2
