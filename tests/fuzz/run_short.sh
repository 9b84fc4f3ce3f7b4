#!/usr/bin/env bash
# The short fuzz run of the test suite: each target for a fixed number of
# inputs from its seed corpus (deterministic seed). Exit 77 (skipped) without
# clang. Long runs: tests/bench/fuzz_long.sh.
#   run_short.sh SOURCE_DIR WORK_DIR [RUNS] [BUILD_DIR]
set -euo pipefail
src=$1 work=$2 runs=${3:-20000} build=${4:-}
here=$(dirname "$0")
"$here/build_fuzzers.sh" "$src" "$work/bin" "$build" || exit $?
# target:seed folder
targets=(request_parser:tests/fuzz/corpus/request config_parser:tests/fuzz/corpus/config
         mesh_parser:tests/fuzz/corpus/mesh image_header:tests/fuzz/corpus/image)
[[ -x $work/bin/fuzz_scene_parser ]] && targets+=(scene_parser:tests/scenes)
for entry in "${targets[@]}"; do
  target=${entry%%:*} seeds=$src/${entry#*:}
  corpus=$work/corpus/$target
  mkdir -p "$corpus"
  "$work/bin/fuzz_$target" -seed=1 -runs="$runs" -max_len=4096 -timeout=10 -rss_limit_mb=1024 \
    "$corpus" "$seeds" 2>"$work/$target.log" ||
    { tail -40 "$work/$target.log"; exit 1; }
  echo "fuzz_$target: $(grep -E "^Done [0-9]+ runs" "$work/$target.log" || tail -2 "$work/$target.log")"
done
