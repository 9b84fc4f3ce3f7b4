#!/usr/bin/env bash
# The short fuzz run of the test suite: each target for a fixed number of
# inputs from its seed corpus (deterministic seed). Exit 77 (skipped) without
# clang. Long runs: tests/bench/fuzz_long.sh.
#   run_short.sh SOURCE_DIR WORK_DIR [RUNS]
set -euo pipefail
src=$1 work=$2 runs=${3:-20000}
here=$(dirname "$0")
"$here/build_fuzzers.sh" "$src" "$work/bin" || exit $?
for target in request_parser config_parser; do
  corpus=$work/corpus/$target
  mkdir -p "$corpus"
  seeds=$src/tests/fuzz/corpus/${target%%_*}
  "$work/bin/fuzz_$target" -seed=1 -runs="$runs" -max_len=4096 -timeout=10 \
    "$corpus" "$seeds" 2>"$work/$target.log" ||
    { tail -40 "$work/$target.log"; exit 1; }
  grep -E "^Done [0-9]+ runs" "$work/$target.log" || tail -2 "$work/$target.log"
done
