#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (-fsanitize=fuzzer,address,undefined)
# and runs each for a bounded time from its seed corpus (tests/fuzz/corpus/).
# Fails on any crash, sanitizer report or invariant violation. Works from a
# fresh clone; everything it writes goes to build/fuzz/.
#
#   bash tests/fuzz/run.sh            # each target for ICLAP_FUZZ_SECONDS (default 60)
#   ICLAP_FUZZ_SECONDS=10 bash tests/fuzz/run.sh stream_parser
#
# Targets: stream_parser (WTS stream parser), dataset_csv (dataset CSV reader
# with a write/read round trip), mesh_obj, mesh_stl, mesh_ply (the mesh
# loaders, one target per format: an input is a mesh file as is) and
# point_file (the point-file reader of `iclap register`); the last four also
# bound the heap a reader takes per input byte (fuzz_heap.hpp). Reproduce a
# finding with
#   build/fuzz/fuzz_<target> build/fuzz/crash-<target>-<hash>
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds="${ICLAP_FUZZ_SECONDS:-60}"
out=build/fuzz
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(stream_parser dataset_csv mesh_obj mesh_stl mesh_ply point_file)

cxx="${ICLAP_FUZZ_CXX:-}"
if [ -z "$cxx" ]; then
  for candidate in clang++ clang++-14 clang++-15 clang++-16; do
    if command -v "$candidate" >/dev/null 2>&1; then cxx="$candidate"; break; fi
  done
fi
if [ -z "$cxx" ]; then
  echo "tests/fuzz/run.sh: no clang++ found (install clang and libclang-rt-dev)" >&2
  exit 1
fi
eigen_flags="$(pkg-config --cflags eigen3 2>/dev/null || echo -I/usr/include/eigen3)"

mkdir -p "$out"
for target in "${targets[@]}"; do
  src="tests/fuzz/fuzz_${target}.cpp"
  if [ ! -f "$src" ]; then
    echo "tests/fuzz/run.sh: unknown target '$target' (no $src)" >&2
    exit 2
  fi
  bin="$out/fuzz_${target}"
  echo "== fuzz_${target}: building with $cxx" >&2
  # shellcheck disable=SC2086
  "$cxx" -std=c++17 -O1 -g -fno-omit-frame-pointer \
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
    -Iinclude -Itests/fuzz $eigen_flags "$src" -o "$bin"
  # The fuzzer adds what it finds to a scratch corpus, never to the committed seeds.
  work="$out/corpus_${target}"
  mkdir -p "$work"
  echo "== fuzz_${target}: running ${seconds}s" >&2
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
    -print_final_stats=1 -artifact_prefix="$out/crash-${target}-" \
    "$work" "tests/fuzz/corpus/${target}" 2>"$out/fuzz_${target}.log" || {
      status=$?
      tail -n 60 "$out/fuzz_${target}.log" >&2
      echo "tests/fuzz/run.sh: fuzz_${target} FAILED (exit $status); input saved as $out/crash-${target}-*" >&2
      exit 1
    }
  grep -E "^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)" \
    "$out/fuzz_${target}.log" >&2 || true
  echo "== fuzz_${target}: no crash" >&2
done
