#!/usr/bin/env bash
# Configures and builds tomomap (Release) into ./build. Installs missing Debian
# packages first. Usage: scripts/build.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} -DBUILD_TESTING=ON "$@"
cmake --build "$BUILD_DIR" -j"$(nproc)"
