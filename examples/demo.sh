#!/usr/bin/env bash
# The main job: installs any missing Debian package, builds the `iclap`
# program in Release and runs the paper's recognition experiment on the
# built-in simulated rig data (simulated once, then cached). Results, figures
# and tables go to results/. Extra arguments go to `iclap evaluate`.
set -euo pipefail
cd "$(dirname "$0")/.."
source .ci/deps.sh
iclap_install_deps
jobs="${ICLAP_JOBS:-2}"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release $(iclap_cmake_launcher_args) >/dev/null
cmake --build build/release -j "$jobs" --target iclap_cli
build/release/examples/iclap evaluate --out results "$@"
