#!/usr/bin/env bash
# Installs the Debian packages vista needs (skips apt when all are present) and builds it
# (file and dpkg-dev: cpack's Debian generator, .ci/package.sh; clang-format: the Style test;
# pybind11-dev, python3-dev, -numpy, -pytest, -pil, -torch: the Python module and its tests).
set -euo pipefail
cd "$(dirname "$0")/.."
PKGS="build-essential cmake ninja-build pkg-config libopenscenegraph-dev openscenegraph libembree-dev
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev libglm-dev libtbb-dev nlohmann-json3-dev libcli11-dev
  libosmium2-dev libprotozero-dev libbz2-dev libexpat1-dev zlib1g-dev libpng-dev libgtest-dev
  libbenchmark-dev xvfb xauth libgl1-mesa-dri jq python3 sumo sumo-tools file dpkg-dev libxml2-utils
  clang-format pybind11-dev python3-dev python3-numpy python3-pytest python3-pil python3-torch"
missing=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
fi
BUILD="${VISTA_BUILD_DIR:-build}"
# Warnings are errors in CI (VISTA_WERROR); a plain build keeps them warnings.
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVISTA_WERROR=ON -DPython3_EXECUTABLE=/usr/bin/python3
cmake --build "$BUILD" -j"$(nproc)"
