#!/usr/bin/env bash
# The demo from a fresh Debian 12 machine: installs what is missing, builds,
# generates a building mapped by three robots (no data from outside needed),
# creates the fleet's keys, runs three tomomapd daemons as separate processes
# talking authenticated, encrypted Fast DDS over loopback (config/local-3-agents/), shows their progress, prints the agreed
# transforms next to the ground truth, and stops them.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
if [ ! -x "$build/daemon/tomomapd" ]; then
  echo "== first run: installing what is missing and building tomomap and tomomapd (on a fresh 2-core"
  echo "   machine 1-5 min of apt, by the mirror, and 2 min of compiling; later runs start in seconds)"
fi
TARGETS="tomomap tomomapd" BUILD_PROGRESS=1 scripts/build.sh
out=demo-out
rm -rf "$out"
echo "== generating a two-floor building seen by three robots (seed 7, low noise)"
"$build/src/cli/tomomap" synth --world indoor --maps 3 --seed 7 --noise low --out "$out/world" | grep -v '^match with'

echo "== creating the fleet's keys (a CA, a certificate per robot, signed DDS Security documents)"
"$build/src/cli/tomomap" fleet-keys --agents alpha,bravo,charlie --out "$out/keys" >/dev/null

# Three daemons on one machine's cores: their OpenMP threads sleep while they
# wait, as the service's do (docs/operations.md, "Sharing the CPU").
export OMP_WAIT_POLICY=passive
pids=()
cleanup() { for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
start=$(date +%s.%N)
for id in alpha bravo charlie; do
  mkdir -p "$out/$id"
  "$build/daemon/tomomapd" --config "config/local-3-agents/$id.toml" 2>"$out/$id.log" &
  pids+=($!)
done
echo "== three daemons started (logs: $out/*.log); waiting for every pair to be agreed"
python3 scripts/demo_watch.py "$out" "$start"
echo
echo "== what an operator sees on robot alpha: tomomap status $out/alpha"
"$build/src/cli/tomomap" status "$out/alpha"
