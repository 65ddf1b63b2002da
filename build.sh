#!/usr/bin/env bash
# ChainTube set-up, build and run — the two commands of the README.
#
#   ./build.sh run    install missing Debian packages, build, run the main job
#   ./build.sh test   install missing Debian packages, build, run the whole test suite, then the
#                     hardening jobs: the suite under ASan + UBSan (preset asan) and a short,
#                     deterministic run of every fuzz target (preset fuzz; seed 1, 40,000 runs
#                     each, scene_import 3,000: CHAINTUBE_FUZZ_RUNS, CHAINTUBE_SCENE_FUZZ_RUNS)
#   ./build.sh sanitize  build the test suite with ASan + UBSan (preset asan, build-asan/), run it
#   ./build.sh fuzz [SECONDS [TARGET...]]  build the libFuzzer targets with clang (preset fuzz,
#                     build-fuzz/) and run each (or the TARGETs: project descriptor gltf
#                     scene_import) for SECONDS (default 60) from its seeds and earlier finds
#   ./build.sh web [PORT]  install emscripten, build, export the samples, then serve the web
#                     viewer (exporters/viewer) on http://127.0.0.1:PORT (default 8000)
#
# Every build also builds the runtime as WebAssembly (preset wasm, build-wasm/) when Debian's
# emscripten is installed; `test` and `web` install it (and chromium, for the browser tests).
#
# Safe to run again: it installs only what is missing and rebuilds incrementally (ccache).
set -euo pipefail
cd "$(dirname "$0")"

# Every dependency is a Debian 12 package. zlib1g-dev is listed by hand because assimp's
# CMake targets link libz.so without any package pulling it in.
debian_packages=(
  build-essential cmake ninja-build ccache pkg-config zlib1g-dev
  libeigen3-dev libassimp-dev libtinygltf-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libbullet-dev
  qt6-base-dev libqt6opengl6-dev libqt6openglwidgets6
  libocct-data-exchange-dev libocct-modeling-algorithms-dev libocct-ocaf-dev
  libocct-visualization-dev
  xvfb xauth libgl1-mesa-dri
  python3 python3-jsonschema
  pybind11-dev python3-dev python3-pytest  # the Python module (exporters/bindings/python) and its tests
  clang-format-14  # the style check (tests/style): every tracked source as .clang-format says
  blender python3-numpy  # the exporter's Blender import test (python3-numpy: its glTF importer)
  mono-devel  # the C ABI's C# test (mcs, mono: P/Invoke into the library as a Unity script does)
)

# Only for `./build.sh fuzz`: clang 14 with the libFuzzer/ASan/UBSan runtimes, llvm-symbolizer.
fuzz_packages=(clang libclang-rt-14-dev llvm)

# For `./build.sh test` and `web`: emscripten builds the WebAssembly runtime; the browser tests
# run the web viewer in chromium (headless, driven by puppeteer-core from npm).
web_packages=(emscripten chromium)

install_missing_packages() {
  local missing=()
  for package in "${debian_packages[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$package")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "build.sh: installing missing Debian packages: ${missing[*]}" >&2
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

# npm packages, pinned by each folder's package-lock.json: the real clients of the tests
# (tests/clients: Khronos glTF-Validator, three.js, puppeteer-core) and the web viewer's three.js
# (exporters/viewer). `npm ci` runs when node_modules is missing or older than the lock file.
install_npm_packages() {
  local folder
  for folder in "$@"; do
    [ "$folder/node_modules/.package-lock.json" -nt "$folder/package-lock.json" ] && continue
    if ! command -v npm >/dev/null; then
      echo "build.sh: npm not found: installing Debian's nodejs and npm" >&2
      local sudo=""
      [ "$(id -u)" -ne 0 ] && sudo="sudo"
      DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
        nodejs npm >/dev/null
    fi
    (cd "$folder" && npm ci --no-audit --no-fund --loglevel=error)
  done
}

# The main job: export the bundled samples to glTF hose rigs in build/export and validate them.
# The engine samples need ../shared/scenes (third-party, never committed); without it only the
# self-contained samples are exported, and the skipped ones are named.
export_samples() {
  local scenes=../shared/scenes
  local projects=(samples/single-hose.ctproj samples/test-rig.ctproj samples/motion-rig.ctproj)
  local roots=()
  if [ -f "$scenes/2CylinderEngine.glb" ]; then
    projects=(samples/*.ctproj)
    roots=(--root "scenes=$scenes")
  else
    echo "build.sh: $scenes/2CylinderEngine.glb is absent: skipping samples/engine.ctproj and" \
         "samples/engine-50-hoses.ctproj (they reference scenes:2CylinderEngine.glb)" >&2
  fi
  ./build/exporters/chaintube export --batch "${projects[@]}" -o build/export -j 2 "${roots[@]}"
  for file in build/export/*.glb; do
    ./build/exporters/chaintube validate "$file" 2>/dev/null
  done
}

build() {
  build_native
  build_wasm
}

build_native() {
  cmake --preset default >/dev/null
  cmake --build --preset default
}

# The runtime as a WebAssembly ES module with its JavaScript API: build-wasm/chaintube/ (only
# the runtime's sources, one Release configuration; the preset sets NODE_PATH for emscripten).
build_wasm() {
  if ! command -v emcmake >/dev/null; then
    echo "build.sh: emscripten is not installed: skipping the WebAssembly runtime (build-wasm/)" >&2
    return 0
  fi
  cmake --preset wasm >/dev/null
  cmake --build --preset wasm
}

# Serves the repository on 127.0.0.1:PORT; the viewer opens the exported test rig.
serve_viewer() {
  local port=${1:-8000}
  echo "build.sh: the web viewer: http://127.0.0.1:$port/exporters/viewer/?file=../../build/export/test-rig.glb" >&2
  echo "build.sh: (any export: Open…, or drop a .glb on the page; Ctrl+C stops the server)" >&2
  python3 -m http.server --bind 127.0.0.1 --directory . "$port"
}

# Prints how long a phase took and the CPU it used (user + sys of every process it waited for),
# so the CI budget can be estimated on a loaded machine, where wall time overstates.
timed() {
  local phase=$1
  shift
  local TIMEFORMAT="build.sh: $phase: %0R s wall, %0U s user + %0S s sys CPU"
  time "$@"
}

sanitize() {
  cmake --preset asan >/dev/null
  cmake --build --preset asan
  ctest --preset asan
}

build_fuzzers() {
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz
}

# run_fuzzers SECONDS [ci|explore] [TARGET...]: runs the fuzz targets (default all) for SECONDS
# each from their seeds; a crash, sanitizer report, leak outside tests/hardening/lsan.supp,
# input slower than 10 s or allocation over 2 GB fails the run.
run_fuzzers() {
  local seconds=$1
  local targets=(project descriptor gltf scene_import)
  [ $# -gt 2 ] && targets=("${@:3}")
  local limit=(-max_total_time="$seconds")
  local ci=
  if [ "${2:-}" = ci ]; then
    # CI: seed 1 and a fixed number of runs (the time only a safety bound) fix the budget; the
    # exploration still differs a little between runs (tests/README.md, "Fuzzing").
    # scene_import starts the assimp reader program for most inputs (the reader processes:
    # assimp's aborts on malformed PLY faces are ImportErrors; its seeds include that file),
    # about 10 ms a run under ASan, so it gets 3,000 runs.
    ci=1
  fi
  for target in "${targets[@]}"; do
    if [ -n "$ci" ]; then
      local runs=${CHAINTUBE_FUZZ_RUNS:-40000}
      [ "$target" = scene_import ] && runs=${CHAINTUBE_SCENE_FUZZ_RUNS:-3000}
      limit=(-seed=1 -runs="$runs" -max_total_time=$((seconds * 4)))
    fi
    # New inputs go to build-fuzz/corpus/<target>; the committed seeds are only read. CI starts
    # from the seeds alone (an emptied build-fuzz/ci-corpus), so every CI run is the same run.
    local corpus="build-fuzz/corpus/$target"
    if [ -n "$ci" ]; then
      corpus="build-fuzz/ci-corpus/$target"
      rm -rf "$corpus"
      echo "build.sh: fuzzing $target: ${limit[*]}" >&2
    else
      echo "build.sh: fuzzing $target for ${seconds} s" >&2
    fi
    mkdir -p "$corpus" "build-fuzz/artifacts/$target"
    # max_allocation_size_mb: the 2 GB allocation limit also in scene_import's reader program
    # (libFuzzer's own limit covers only the fuzzer's process).
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}max_allocation_size_mb=2048" \
    LSAN_OPTIONS="suppressions=$PWD/tests/hardening/lsan.supp:print_suppressions=0" \
      "build-fuzz/tests/fuzz/${target}_fuzzer" "${limit[@]}" -rss_limit_mb=2048 \
      -timeout=10 -print_final_stats=1 -artifact_prefix="build-fuzz/artifacts/$target/" \
      "$corpus" "tests/fuzz/corpus/$target"
  done
}

case "${1:-}" in
  run)
    install_missing_packages
    build
    export_samples
    ;;
  test)
    install_missing_packages "${fuzz_packages[@]}" "${web_packages[@]}"
    install_npm_packages tests/clients exporters/viewer
    timed "build (default)" build_native
    timed "build (wasm)" build_wasm
    timed "tests (default)" ctest --preset default
    # The hardening jobs of CI (tests/README.md; their cost in tests/bench/PERFORMANCE-NOTES.md).
    timed "build + tests (asan)" sanitize
    timed "build (fuzz)" build_fuzzers
    timed "fuzzing" run_fuzzers "${CHAINTUBE_FUZZ_SECONDS:-25}" ci
    ;;
  sanitize)
    install_missing_packages
    sanitize
    ;;
  fuzz)
    install_missing_packages "${fuzz_packages[@]}"
    build_fuzzers
    run_fuzzers "${2:-60}" explore "${@:3}"
    ;;
  web)
    install_missing_packages "${web_packages[@]}"
    install_npm_packages exporters/viewer
    build
    export_samples
    serve_viewer "${2:-8000}"
    ;;
  *)
    echo "usage: $0 run|test|sanitize|fuzz [SECONDS [TARGET...]]|web [PORT]" >&2
    exit 2
    ;;
esac
