#!/usr/bin/env bash
# Installs tomomap the two ways users do and runs what got installed:
#   1. scripts/install.sh (what the Dockerfile runs) into a staging DESTDIR;
#   2. the .deb that CPack builds, unpacked into a staging root.
# Checks the files are where the docs say, the .deb depends on Debian's runtime
# packages, the installed binaries run, and systemd accepts the installed unit.
# Usage: test_install.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
SRC=$1
BUILD=$2
STAGE=$(mktemp -d /tmp/tomomap-install-XXXXXX)
trap 'rm -rf "$STAGE"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
check_file() { [ -f "$1" ] || fail "$1 was not installed"; }

echo "== scripts/install.sh into DESTDIR=$STAGE/dest, PREFIX=/opt/tomomap"
DESTDIR="$STAGE/dest" PREFIX=/opt/tomomap BUILD_DIR="$BUILD" "$SRC/scripts/install.sh" > "$STAGE/install.log" 2>&1 ||
  { cat "$STAGE/install.log"; fail "scripts/install.sh failed"; }
root="$STAGE/dest/opt/tomomap"
for f in bin/tomomap bin/tomomapd bin/tomomap-baseline lib/systemd/system/tomomapd.service etc/tomomap/tomomapd.toml \
         share/doc/tomomap/README.md share/doc/tomomap/operations.md share/doc/tomomap/configuration.md \
         share/doc/tomomap/examples/tomomapd.toml; do
  check_file "$root/$f"
done
grep -q "^ExecStart=/opt/tomomap/bin/tomomapd " "$root/lib/systemd/system/tomomapd.service" ||
  fail "the unit does not start the installed binary: $(grep ExecStart "$root/lib/systemd/system/tomomapd.service")"
"$root/bin/tomomap" --version | grep -q "^tomomap [0-9]" || fail "installed tomomap --version"

echo "== cpack -G DEB"
(cd "$BUILD" && cpack -G DEB -B "$STAGE/pkg" > "$STAGE/cpack.log" 2>&1) || { cat "$STAGE/cpack.log"; fail "cpack"; }
deb=$(ls "$STAGE"/pkg/tomomap_*_amd64.deb)
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for p in libfastrtps2.9 libfastcdr1 libopencv-core406 libfftw3-single3 libpcl-common1.13 libpcl-io1.13 liblzf1 libsystemd0 libtomlplusplus3; do
  echo "$depends" | grep -q "$p" || fail "the .deb does not depend on $p"
done
echo "$depends" | grep -q -- "-dev" && fail "the .deb depends on a -dev package"
dpkg-deb -e "$deb" "$STAGE/control"
grep -qx /etc/tomomap/tomomapd.toml "$STAGE/control/conffiles" || fail "the config is not a conffile"

echo "== the .deb unpacked into $STAGE/root"
dpkg-deb -x "$deb" "$STAGE/root"
r="$STAGE/root"
for f in usr/bin/tomomap usr/bin/tomomapd usr/bin/tomomap-baseline usr/lib/systemd/system/tomomapd.service \
         usr/lib/tomomap/tomomap_pcl_io.so etc/tomomap/tomomapd.toml usr/share/doc/tomomap/operations.md; do
  check_file "$r/$f"
done
grep -q "^ExecStart=/usr/bin/tomomapd --config %E/tomomap/tomomapd.toml" "$r/usr/lib/systemd/system/tomomapd.service" ||
  fail "the packaged unit's ExecStart"

# The installed binaries work on their own: generate, match, check the config.
"$r/usr/bin/tomomapd" --version | grep -q "^tomomapd [0-9]" || fail "tomomapd --version"
"$r/usr/bin/tomomap" synth -o "$STAGE/world" -n 2 -s 5 --scale 0.5 > /dev/null || fail "installed tomomap synth"
"$r/usr/bin/tomomap" match "$STAGE/world/map_0.pcd" "$STAGE/world/map_1.pcd" --grid 0.05 \
  --gt-target "$STAGE/world/map_0-gtpose.txt" --gt-source "$STAGE/world/map_1-gtpose.txt" > "$STAGE/match.txt" ||
  { cat "$STAGE/match.txt"; fail "installed tomomap match"; }
grep -q "T_target_source" "$STAGE/match.txt" || fail "no transform printed"
# Binary PCDs are read without PCL's io (and the 60 libraries it maps); synth's
# writing above and a PLY load through the module, found next to the binary.
LD_DEBUG=libs "$r/usr/bin/tomomap" match "$STAGE/world/map_0.pcd" "$STAGE/world/map_1.pcd" --grid 0.1 2>&1 >/dev/null |
  grep -q "libpcl_io" && fail "matching binary PCDs loaded PCL's io"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n' \
  > "$STAGE/three.ply"
out=$("$r/usr/bin/tomomap" match "$STAGE/three.ply" "$STAGE/three.ply" 2>&1) && fail "a 3-point map was matched"
echo "$out" | grep -q "has only 3 points" || fail "the installed tomomap did not read a PLY: $out"
# A binary copied away from its module says what is missing, and exits 2.
mkdir -p "$STAGE/lonely" && cp "$r/usr/bin/tomomap" "$STAGE/lonely/"
rc=0
out=$("$STAGE/lonely/tomomap" match "$STAGE/three.ply" "$STAGE/three.ply" 2>&1) || rc=$?
[ "$rc" -eq 2 ] || fail "without the module: exit $rc, expected 2 (bad input)"
echo "$out" | grep -q "need the module tomomap_pcl_io.so" || fail "no clear error without the module: $out"
"$r/usr/bin/tomomapd" --config "$r/etc/tomomap/tomomapd.toml" --check | grep -q "agent = robot1" ||
  fail "the packaged example config does not pass --check"

if command -v systemd-analyze > /dev/null; then
  echo "== systemd-analyze verify (the packaged unit, started from the unpacked binary)"
  mkdir -p "$STAGE/units"
  sed "s#^ExecStart=/usr/bin/tomomapd#ExecStart=$r/usr/bin/tomomapd#" "$r/usr/lib/systemd/system/tomomapd.service" \
    > "$STAGE/units/tomomapd.service"
  out=$(systemd-analyze verify "$STAGE/units/tomomapd.service" 2>&1) || { echo "$out"; fail "systemd-analyze verify"; }
  # verify exits 0 on unknown settings and bad values: any complaint about the unit fails the test.
  if echo "$out" | grep "tomomapd.service"; then fail "systemd-analyze complained about the unit"; fi
else
  echo "systemd-analyze not installed: unit not verified"
fi
echo "PASS"
