#!/usr/bin/env bash
# Long fuzz run of procamd's parsers: the control protocol's requests, procamd.toml,
# scene files, OBJ/PLY meshes and image headers (the test suite runs a short pass:
# tests/fuzz/run_short.sh). Each target runs RUNS inputs (10 million by default)
# from its corpus, which persists in WORK_DIR between runs; a crash stops the run
# and is written there as crash-*. The scene parser links BUILD_DIR's libraries.
#   tests/bench/fuzz_long.sh [RUNS=10000000] [WORK_DIR=build/fuzz-long] [BUILD_DIR=build]
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-10000000} work=${2:-build/fuzz-long} build=${3:-build}
root=$PWD
[[ $build == /* ]] || build=$root/$build
tests/fuzz/build_fuzzers.sh "$root" "$work/bin" "$build"
targets=(request_parser:tests/fuzz/corpus/request config_parser:tests/fuzz/corpus/config
         mesh_parser:tests/fuzz/corpus/mesh image_header:tests/fuzz/corpus/image
         scene_parser:tests/scenes)
for entry in "${targets[@]}"; do
  target=${entry%%:*} seeds=$root/${entry#*:}
  corpus=$work/corpus/$target
  mkdir -p "$corpus"
  start=$(date +%s)
  (cd "$work" && "bin/fuzz_$target" -runs="$runs" -max_len=65536 -timeout=10 \
      -rss_limit_mb=2048 -print_final_stats=1 "corpus/$target" "$seeds" \
      >"$target.log" 2>&1) ||
    { tail -30 "$work/$target.log"; echo "fuzz_$target found a problem: see $work"; exit 1; }
  echo "fuzz_$target: $(grep -E '^Done [0-9]+ runs' "$work/$target.log") ($(( $(date +%s) - start )) s)," \
       "$(grep -E 'stat::number_of_executed_units' "$work/$target.log" | awk '{print $2}') executions," \
       "corpus $(ls "$work/corpus/$target" | wc -l) inputs"
done
