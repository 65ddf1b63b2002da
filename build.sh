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

build() {
  cmake --preset default >/dev/null
  cmake --build --preset default
}

case "${1:-}" in
  run)
    install_missing_packages
    build
    ./build/exporters/chaintube demo
    ;;
  test)
    install_missing_packages
    build
    ctest --preset default
    ;;
  *)
    echo "usage: $0 run|test" >&2
    exit 2
    ;;
esac
