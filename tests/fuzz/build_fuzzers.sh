#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan + libFuzzer) into
# OUT_DIR, rebuilding only when a source changed. Exit 77 without clang.
# The scene parser needs the rest of the virtual rig: it is built only with
# BUILD_DIR, a configured build whose static libraries it links (the parser's own
# sources are compiled here, instrumented).
#   build_fuzzers.sh SOURCE_DIR OUT_DIR [BUILD_DIR]
set -euo pipefail
src=$1 out=$2 build=${3:-}
CXX=${FUZZ_CXX:-clang++}
command -v "$CXX" >/dev/null || { echo "no $CXX: fuzzers not built"; exit 77; }
mkdir -p "$out"
flags=(-std=c++20 -O1 -gline-tables-only -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -I"$src/daemon" -I"$src/pipelines" -I"$src/plugins/include" -I"$src/drivers"
       -I/usr/include/eigen3 -I/usr/include/opencv4
       -DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1)
build() {  # name sources... -- libs...
  local name=$1; shift
  local srcs=() libs=()
  while [[ $1 != -- ]]; do srcs+=("$src/$1"); shift; done; shift
  libs=("$@")
  local bin=$out/$name newest
  newest=$(ls -t "${srcs[@]}" "$src"/daemon/*.hpp "$src"/drivers/sim/*.hpp \
             "$src"/drivers/content/*.hpp | head -1)
  if [[ -x $bin && $bin -nt $newest ]]; then return 0; fi
  "$CXX" "${flags[@]}" "${srcs[@]}" -o "$bin" "${libs[@]}"
}
build fuzz_request_parser tests/fuzz/fuzz_request_parser.cpp daemon/protocol.cpp --
build fuzz_config_parser tests/fuzz/fuzz_config_parser.cpp daemon/config.cpp daemon/log.cpp \
  pipelines/core/error.cpp -- -ltomlplusplus
build fuzz_mesh_parser tests/fuzz/fuzz_mesh_parser.cpp drivers/sim/mesh_io.cpp \
  pipelines/core/error.cpp --
build fuzz_image_header tests/fuzz/fuzz_image_header.cpp drivers/content/image_header.cpp \
  pipelines/core/error.cpp --
if [[ -n $build ]]; then
  libs=()
  for lib in drivers/sim/libprocam_sim.a pipelines/rig/libprocam_rig.a \
             pipelines/keystone/libprocam_keystone.a pipelines/calibration/libprocam_calibration.a \
             pipelines/structured_light/libprocam_apriltag_grid.a \
             pipelines/structured_light/libprocam_structured_light.a \
             pipelines/geometry/libprocam_geometry.a pipelines/libprocam_core.a; do
    [[ -f $build/$lib ]] && libs+=("$build/$lib")
  done
  # A build made with other sanitizers (asan, tsan) does not link with this one:
  # the scene fuzzer is then left out, with a note.
  build fuzz_scene_parser tests/fuzz/fuzz_scene_parser.cpp drivers/sim/scene_toml.cpp \
    drivers/sim/toml_fields.cpp drivers/sim/mesh_io.cpp -- \
    -Wl,--start-group "${libs[@]}" -Wl,--end-group -ltomlplusplus -lceres -lglog \
    -lapriltag -lapriltag-utils -lopencv_aruco -lopencv_calib3d -lopencv_imgproc -lopencv_core \
    2>"$out/scene_parser.link.log" ||
    { rm -f "$out/fuzz_scene_parser"; echo "fuzz_scene_parser not built: $build's libraries" \
        "do not link with clang's sanitizers (see $out/scene_parser.link.log)"; }
fi
