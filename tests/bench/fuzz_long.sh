#!/usr/bin/env bash
# Long fuzz run of procamd's request and config parsers (the test suite runs a
# short pass: tests/fuzz/run_short.sh). Corpora persist in WORK_DIR between runs;
# crashes are written there as crash-* files.
#   tests/bench/fuzz_long.sh [SECONDS_PER_TARGET=600] [WORK_DIR=build/fuzz-long]
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-600} work=${2:-build/fuzz-long}
root=$PWD
tests/fuzz/build_fuzzers.sh "$root" "$work/bin"
jobs=$(nproc)
for target in request_parser config_parser; do
  corpus=$work/corpus/$target
  mkdir -p "$corpus"
  echo "fuzz_$target: ${seconds}s on $jobs worker(s), corpus $corpus"
  (cd "$work" && "bin/fuzz_$target" -max_total_time="$seconds" -max_len=131072 -timeout=10 \
      -jobs="$jobs" -workers="$jobs" -print_final_stats=1 \
      "corpus/$target" "$root/tests/fuzz/corpus/${target%%_*}" 2>&1 | tail -20) ||
    { echo "fuzz_$target found a problem: see $work"; exit 1; }
done
