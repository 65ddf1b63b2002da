#!/usr/bin/env bash
# ChainTube set-up, build and run — the two commands of the README.
#
#   ./build.sh run    install missing Debian packages, build, run the main job
#   ./build.sh test   install missing Debian packages, build, run the whole test suite
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
  blender python3-numpy  # the exporter's Blender import test (python3-numpy: its glTF importer)
)

install_missing_packages() {
  local missing=()
  for package in "${debian_packages[@]}"; do
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

# The real glTF clients of the exporter tests (Khronos glTF-Validator, three.js) come from npm,
# pinned by tests/clients/package-lock.json; installed once, when node_modules is missing.
install_test_clients() {
  [ -d tests/clients/node_modules ] && return 0
  if ! command -v npm >/dev/null; then
    echo "build.sh: npm not found: installing Debian's nodejs and npm" >&2
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
      nodejs npm >/dev/null
  fi
  (cd tests/clients && npm ci --no-audit --no-fund --loglevel=error)
}

# The main job: export the bundled samples to glTF hose rigs in build/export and validate them.
# The engine samples need ../shared/scenes (third-party, never committed); without it only the
# self-contained samples are exported, and the skipped ones are named.
export_samples() {
  local scenes=../shared/scenes
  local projects=(samples/single-hose.ctproj samples/test-rig.ctproj)
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
  cmake --preset default >/dev/null
  cmake --build --preset default
}

case "${1:-}" in
  run)
    install_missing_packages
    build
    export_samples
    ;;
  test)
    install_missing_packages
    install_test_clients
    build
    ctest --preset default
    ;;
  *)
    echo "usage: $0 run|test" >&2
    exit 2
    ;;
esac
