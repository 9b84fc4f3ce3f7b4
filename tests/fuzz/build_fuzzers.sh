#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan + libFuzzer) into
# OUT_DIR, rebuilding only when a source changed. Exit 77 without clang.
#   build_fuzzers.sh SOURCE_DIR OUT_DIR
set -euo pipefail
src=$1 out=$2
CXX=${FUZZ_CXX:-clang++}
command -v "$CXX" >/dev/null || { echo "no $CXX: fuzzers not built"; exit 77; }
mkdir -p "$out"
flags=(-std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -I"$src/daemon" -I"$src/pipelines" -I"$src/plugins/include"
       -DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1)
build() {  # name sources... -- libs...
  local name=$1; shift
  local srcs=() libs=()
  while [[ $1 != -- ]]; do srcs+=("$src/$1"); shift; done; shift
  libs=("$@")
  local bin=$out/$name newest
  newest=$(ls -t "${srcs[@]}" "$src"/daemon/*.hpp | head -1)
  if [[ -x $bin && $bin -nt $newest ]]; then return 0; fi
  "$CXX" "${flags[@]}" "${srcs[@]}" -o "$bin" "${libs[@]}"
}
build fuzz_request_parser tests/fuzz/fuzz_request_parser.cpp daemon/protocol.cpp --
build fuzz_config_parser tests/fuzz/fuzz_config_parser.cpp daemon/config.cpp daemon/log.cpp \
  pipelines/core/error.cpp -- -ltomlplusplus
