#!/usr/bin/env bash
# The demo from a fresh Debian 12 machine: installs what is missing, builds,
# generates an indoor and an outdoor world (no data from outside needed) and
# matches each pair of maps, printing the transform next to the ground truth.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh >/dev/null
tomomap=${BUILD_DIR:-build}/src/cli/tomomap
out=${DEMO_DIR:-$(mktemp -d /tmp/tomomap-demo.XXXXXX)}
for world in indoor outdoor; do
  echo "== $world world: generating two overlapping maps (seed 7, low noise)"
  $tomomap synth --world "$world" --seed 7 --noise low --out "$out/$world" --progress | grep -v '^match with'
  grid=$(grep -o '"grid": [0-9.]*' "$out/$world/scene.json" | awk '{print $2}')
  echo "== $world world: matching map_1 (source) into map_0 (target) at grid $grid m"
  $tomomap match "$out/$world/map_0.pcd" "$out/$world/map_1.pcd" --grid "$grid" \
    --gt-target "$out/$world/map_0-gtpose.txt" --gt-source "$out/$world/map_1-gtpose.txt" \
    --json "$out/$world/result.json"
  echo
done
echo "maps and results are in $out"
