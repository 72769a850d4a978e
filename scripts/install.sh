#!/usr/bin/env bash
# Builds tomomap (Release) and installs it: tomomap, tomomap-baseline, tomomapd,
# the systemd unit, the example config and the docs. The Dockerfile runs this;
# so can a robot. Needs root for the package step and for a system prefix.
#
#   PREFIX    install prefix (default /usr/local; the unit and config follow it:
#             PREFIX/lib/systemd/system, PREFIX/etc/tomomap, or /etc/tomomap for /usr)
#   DESTDIR   staging root, as for any `make install`
#   BUILD_DIR build folder (default build-install); an existing one is reused as
#             configured, so the test build can be installed without rebuilding
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build-install}
PREFIX=${PREFIX:-/usr/local}
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF
fi
cmake --build "$BUILD_DIR" -j"$(nproc)"
cmake --install "$BUILD_DIR" --prefix "$PREFIX"
echo "installed into ${DESTDIR:-}$PREFIX"
