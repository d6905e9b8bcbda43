#!/usr/bin/env bash
# The main demo: installs any missing Debian package, builds the `iclap`
# program in Release and runs it on the built-in example.
set -euo pipefail
cd "$(dirname "$0")/.."
source .ci/deps.sh
iclap_install_deps
jobs="${ICLAP_JOBS:-2}"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release $(iclap_cmake_launcher_args) >/dev/null
cmake --build build/release -j "$jobs" --target iclap_cli
build/release/examples/iclap register examples/data/wrench_model.txt examples/data/wrench_test.txt \
  --transform planar --weights 1,1,1,0.01 "$@"
