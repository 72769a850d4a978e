#!/usr/bin/env bash
# Configures and builds tomomap into ./build (Release, warnings as errors, unity
# build: the heavy PCL, Fast DDS and JSON headers are compiled once per batch
# of sources rather than once per file, about half the compile time).
# Installs missing Debian packages first.
# Usage: scripts/build.sh [extra cmake args...]; from the environment:
#   BUILD_DIR, BUILD_TYPE, TARGETS (space-separated, default: everything),
#   BUILD_PROGRESS=1: one line per percent step with the elapsed time instead of
#   the compiler's lines (the full log is kept in BUILD_DIR/build.log and shown
#   on failure).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build}
targets=()
for t in ${TARGETS:-}; do targets+=(--target "$t"); done
configure=(cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DBUILD_TESTING=ON
           -DTOMOMAP_WERROR=ON -DCMAKE_UNITY_BUILD=ON "$@")
build=(cmake --build "$BUILD_DIR" -j"$(nproc)" "${targets[@]}")

if [ "${BUILD_PROGRESS:-0}" != 1 ]; then
  "${configure[@]}"
  "${build[@]}"
  exit 0
fi

mkdir -p "$BUILD_DIR"
log="$BUILD_DIR/build.log"
start=$SECONDS
elapsed() { printf '%dm %02ds' $(((SECONDS - start) / 60)) $(((SECONDS - start) % 60)); }
if ! "${configure[@]}" >"$log" 2>&1; then
  cat "$log" >&2
  echo "build: configuring failed (log above, also in $log)" >&2
  exit 1
fi
echo "build: configured in $(elapsed); compiling ${TARGETS:-everything} on $(nproc) cores"
# The build's own percentage, printed when it moves forward (make counts each
# target's steps anew, so it can go back; a line each, so that a log or a pipe
# reads as well as a terminal).
set +e
"${build[@]}" 2>&1 | tee -a "$log" | {
  last=-1
  while IFS= read -r line; do
    if [[ $line =~ ^\[\ *([0-9]+)%\] ]] && [ "${BASH_REMATCH[1]}" -gt "$last" ]; then
      last=${BASH_REMATCH[1]}
      printf 'build: %3d%%  %s\n' "$last" "$(elapsed)"
    fi
  done
}
status=${PIPESTATUS[0]}
set -e
if [ "$status" -ne 0 ]; then
  grep -v '^\[ *[0-9]*%\]' "$log" >&2 || true
  echo "build: failed after $(elapsed) (the compiler's messages above; the whole log in $log)" >&2
  exit "$status"
fi
echo "build: done in $(elapsed)"
