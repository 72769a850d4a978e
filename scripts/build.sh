#!/usr/bin/env bash
# Configures and builds tomomap into ./build (Release, warnings as errors).
# Installs missing Debian packages first.
# Usage: scripts/build.sh [extra cmake args...]; BUILD_DIR, BUILD_TYPE and
# TARGETS (space-separated, default: everything) from the environment.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DBUILD_TESTING=ON -DTOMOMAP_WERROR=ON "$@"
targets=()
for t in ${TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$BUILD_DIR" -j"$(nproc)" "${targets[@]}"
