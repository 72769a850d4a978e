#!/usr/bin/env bash
# Installs the Debian 12 packages tomomap needs to build, test and run.
# Idempotent: packages already present are skipped, and apt is not touched at all
# when nothing is missing. Needs root (or sudo) only when something must be installed.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libpcl-dev libopenmpi-dev libeigen3-dev libopencv-dev liboctomap-dev libceres-dev libfftw3-dev
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  cyclonedds-dev cyclonedds-tools  # the tests' ROS 2 node: a second DDS vendor, rmw_cyclonedds's
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
  libssl-dev liblzf-dev libboost-dev  # Boost.Math: the t and normal distributions
  libgtest-dev libgmock-dev libbenchmark-dev libsystemd-dev zlib1g-dev libpng-dev
  python3 time
  file dpkg-dev systemd  # CPack's .deb dependency scan; systemd-analyze checks the unit in the tests
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi

# apt's own lines go to a log, shown in full if it fails; the terminal gets a
# line per phase with the time it took.
log=$(mktemp /tmp/tomomap-install-deps.XXXXXX.log)
start=$SECONDS
run() {
  if ! "$@" >>"$log" 2>&1; then
    cat "$log" >&2
    echo "install-deps: '$*' failed (apt's output above, also in $log)" >&2
    exit 1
  fi
}
export DEBIAN_FRONTEND=noninteractive
echo "install-deps: ${#missing[@]} of ${#PACKAGES[@]} packages missing: ${missing[*]}"
echo "install-deps: updating the package lists"
run $SUDO apt-get update
echo "install-deps: downloading and installing (a fresh Debian 12 machine takes 1-5 min, by the mirror; apt's log: $log)"
run $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
echo "install-deps: done in $((SECONDS - start)) s"
rm -f "$log"
