#!/usr/bin/env bash
# fahr as a lab machine gets it: installed into a temporary prefix, the build
# folder and the source tree's deployment data out of the way (a private
# mount namespace lays empty folders over them), a one-host station run from
# the prefix with fahr_lab in a loopback-only network namespace; the systemd
# units checked with systemd-analyze verify; a project outside fahr built
# against find_package(fahr); the Debian package built and listed.
#
#   tests/install/install_test.sh BUILD_DIR
#
# Needs root (namespaces, mounts) and a full build; fails, never skips.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
[ "$(id -u)" -eq 0 ] || { echo "install_test: needs root (namespaces and mounts)" >&2; exit 1; }
work=$(mktemp -d /tmp/fahr-install-test-XXXXXX)
trap 'rm -rf "$work"' EXIT
prefix="$work/usr"
fail() { echo "install_test: FAIL: $*" >&2; exit 1; }

echo "install_test: cmake --install into $prefix"
cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1 ||
  { tail -n 20 "$work/install.log" >&2; fail "cmake --install"; }
for f in bin/fahr_lab bin/fahr_fem_service bin/fahr_haptic_service bin/fahr_device_gateway \
         bin/fahr_logger bin/fahr_run_summary bin/fahr_dds_check \
         share/fahr/deployment/scenes/neonatal_intubation.yaml \
         share/fahr/deployment/labs/one_host.yaml share/fahr/deployment/dds/fastdds_loopback.xml \
         share/fahr/meshes/neonatal/tongue.node lib/cmake/fahr/fahrConfig.cmake \
         lib/cmake/fahr/fahrTargets.cmake lib/systemd/system/fahr-fem@.service \
         lib/systemd/system/fahr-station@.target lib/sysctl.d/60-fahr.conf; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done

echo "install_test: systemd-analyze verify"
units="$work/units"
mkdir -p "$units"
for unit in "$prefix"/lib/systemd/system/fahr-*@.service; do
  name=$(basename "$unit" .service)
  cp "$unit" "$units/$(basename "$unit")"
  ln -s "$(basename "$unit")" "$units/${name}t1.service"
done
cp "$prefix/lib/systemd/system/fahr-station@.target" "$units/"
ln -s fahr-station@.target "$units/fahr-station@t1.target"
(cd "$units" && SYSTEMD_LOG_LEVEL=warning systemd-analyze verify --man=no ./*@t1.service ./*@t1.target) \
  >"$work/verify.log" 2>&1 || { cat "$work/verify.log" >&2; fail "systemd-analyze verify"; }
if grep -v -E "^$|Failed to prepare filename|Cannot add dependency job" "$work/verify.log" | grep -q .; then
  cat "$work/verify.log" >&2
  fail "systemd-analyze verify reported problems"
fi

echo "install_test: a project outside fahr: find_package(fahr), fahr::scene"
cmake -S "$repo/tests/install/consumer" -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$work/consumer.log" 2>&1 ||
  { tail -n 30 "$work/consumer.log" >&2; fail "configuring the consumer"; }
cmake --build "$work/consumer" >>"$work/consumer.log" 2>&1 ||
  { tail -n 30 "$work/consumer.log" >&2; fail "building the consumer"; }

echo "install_test: a station from the prefix, the build and source data hidden"
cat >"$work/station.sh" <<EOF
set -euo pipefail
mount -t tmpfs none "$build"
mount -t tmpfs none "$repo/deployment"
mount -t tmpfs none "$repo/meshes"
[ ! -e "$build/CMakeCache.txt" ] && [ ! -e "$repo/deployment/scenes" ]
"$work/consumer/fahr_consumer"
export FAHR_RUN_ROOT="$work/runs"
"$prefix/bin/fahr_lab" check "$prefix/share/fahr/deployment/labs/one_host.yaml" >/dev/null
timeout 240 "$prefix/bin/fahr_lab" up "$prefix/share/fahr/deployment/labs/one_host.yaml" solo --detach
sleep 4
"$prefix/bin/fahr_lab" status solo
"$prefix/bin/fahr_lab" down solo
EOF
unshare --mount --propagation private "$repo/tests/run_in_netns.sh" bash "$work/station.sh" \
  >"$work/station.log" 2>&1 || { cat "$work/station.log" >&2; fail "the installed station"; }
cat "$work/station.log"
grep -q "fahr_consumer: scene 'neonatal_intubation'" "$work/station.log" || fail "the consumer did not load the installed scene"
poses=$(awk -F'|' '/DevicePose samples/ { gsub(/ /, "", $3); print $3 }' "$work/runs/solo/summary.log")
[ "${poses:-0}" -gt 0 ] || fail "the installed station's summary heard no DevicePose"
echo "install_test: the installed station's summary heard $poses DevicePoses"

echo "install_test: cpack -G DEB"
(cd "$build" && cpack -G DEB -B "$work/pkg" >"$work/cpack.log" 2>&1) ||
  { tail -n 20 "$work/cpack.log" >&2; fail "cpack"; }
deb=$(ls "$work"/pkg/fahr_*.deb)
dpkg-deb -c "$deb" >"$work/deb.list"
for f in ./usr/bin/fahr_lab ./usr/share/fahr/meshes/neonatal/tongue.node \
         ./usr/lib/systemd/system/fahr-haptic@.service ./usr/lib/cmake/fahr/fahrConfig.cmake; do
  grep -q " $f\$" "$work/deb.list" || fail "$f is not in $(basename "$deb")"
done
depends=$(dpkg-deb -f "$deb" Depends)
for d in libfastrtps2.9 libddsc0debian libyaml-cpp0.7 libcholmod3; do
  echo "$depends" | grep -q "$d" || fail "the package does not depend on $d"
done
echo "install_test: $(basename "$deb"): $(wc -l <"$work/deb.list") entries, $(du -h "$deb" | cut -f1); Depends: $depends"
echo "install_test: passed"
