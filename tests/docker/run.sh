#!/usr/bin/env bash
# The container fleet, run for real on this machine's own Docker Engine:
# builds the tomomapd image (docker/Dockerfile), starts the three-robot compose
# fleet (docker/compose.yaml), waits until each robot holds every pair's agreed
# transform, shows `tomomap status` inside a container, and tears down what it
# started. Prints the image size and the time to agreement. Not part of CI: the
# image build alone takes minutes. Run as root from anywhere:
#
#   tests/docker/run.sh
#
# Where no registry is reachable the debian:12 base is made with debootstrap
# and `docker import`. Where no Docker Engine runs, dockerd is started with its
# default bridge on a documentation range (198.51.100.0/24: these machines
# carry no traffic on private ranges) and stopped again by its PID.
#   WORK      scratch folder (default /tmp/tomomap-docker): dockerd's data, the base's root
#   DEADLINE  seconds to wait for agreement (default 600)
set -euo pipefail
cd "$(dirname "$0")/../.."
WORK=${WORK:-/tmp/tomomap-docker}
DEADLINE=${DEADLINE:-600}
project=tomomapdocker
mkdir -p "$WORK"
say() { echo "== $*"; }

need=()
command -v dockerd >/dev/null || need+=(docker.io)
command -v debootstrap >/dev/null || need+=(debootstrap)
command -v docker-compose >/dev/null || docker compose version >/dev/null 2>&1 || need+=(docker-compose)
if [ ${#need[@]} -gt 0 ]; then
  say "installing ${need[*]}"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${need[@]}" >"$WORK/apt.log" 2>&1 || {
    cat "$WORK/apt.log"
    exit 1
  }
fi
compose() {
  if docker compose version >/dev/null 2>&1; then docker compose -p "$project" -f docker/compose.yaml "$@"
  else docker-compose -p "$project" -f docker/compose.yaml "$@"; fi
}

dockerd_pid=""
cleanup() {
  set +e
  compose down -v --remove-orphans >/dev/null 2>&1
  if [ -n "$dockerd_pid" ]; then
    kill "$dockerd_pid" 2>/dev/null
    for _ in $(seq 60); do kill -0 "$dockerd_pid" 2>/dev/null || break; sleep 0.5; done
  fi
}
trap cleanup EXIT

if ! docker info >/dev/null 2>&1; then
  say "starting dockerd (bridge 198.51.100.1/24, data in $WORK)"
  export DOCKER_HOST="unix://$WORK/docker.sock"
  dockerd --bip 198.51.100.1/24 --data-root "$WORK/data" --exec-root "$WORK/exec" \
    --pidfile "$WORK/dockerd.pid" -H "$DOCKER_HOST" >"$WORK/dockerd.log" 2>&1 &
  dockerd_pid=$!
  for _ in $(seq 120); do docker info >/dev/null 2>&1 && break; sleep 0.5; done
  docker info >/dev/null 2>&1 || { tail -20 "$WORK/dockerd.log"; exit 1; }
fi

if ! docker image inspect debian:12 >/dev/null 2>&1 && ! timeout 60 docker pull debian:12 >/dev/null 2>&1; then
  say "no debian:12 to pull: making one with debootstrap"
  t0=$SECONDS
  rm -rf "$WORK/rootfs"
  debootstrap --variant=minbase bookworm "$WORK/rootfs" http://deb.debian.org/debian >"$WORK/debootstrap.log" 2>&1 || {
    tail -20 "$WORK/debootstrap.log"
    exit 1
  }
  tar -C "$WORK/rootfs" -c . | docker import - debian:12 >/dev/null
  rm -rf "$WORK/rootfs"
  say "base imported in $((SECONDS - t0)) s"
fi

say "building the image (docker build --network host -f docker/Dockerfile)"
t0=$SECONDS
docker build --network host -f docker/Dockerfile -t tomomap:latest . >"$WORK/build.log" 2>&1 || {
  tail -40 "$WORK/build.log"
  exit 1
}
size=$(docker image inspect -f '{{.Size}}' tomomap:latest)
say "image built in $((SECONDS - t0)) s: tomomap:latest, $((size / 1000000)) MB"

say "starting the fleet (docker/compose.yaml: world, alpha, bravo, charlie)"
compose up -d --no-build >"$WORK/compose.log" 2>&1 || { cat "$WORK/compose.log"; exit 1; }
t0=$SECONDS
agreed() {  # every robot holds all three pairs' transforms
  for agent in alpha bravo charlie; do
    compose exec -T "$agent" cat /var/lib/tomomap/transforms.json 2>/dev/null |
      python3 -c 'import json, sys; sys.exit(0 if len(json.load(sys.stdin)["transforms"]) == 3 else 1)' 2>/dev/null ||
      return 1
  done
}
until agreed; do
  if [ $((SECONDS - t0)) -ge "$DEADLINE" ]; then
    say "no agreement within $DEADLINE s; the robots' logs:"
    compose logs --tail 30 alpha bravo charlie
    exit 1
  fi
  sleep 1
done
say "every robot holds every pair's transform $((SECONDS - t0)) s after the fleet started"
say "what an operator sees inside robot alpha: tomomap status /var/lib/tomomap"
compose exec -T alpha tomomap status /var/lib/tomomap
say "tearing down"
