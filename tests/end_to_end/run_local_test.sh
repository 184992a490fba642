#!/usr/bin/env bash
# Runs deployment/run_local.sh for 8 s inside a loopback-only namespace and
# checks its summary: the haptic service answered DevicePoses (ForceCommand
# samples > 0), the FEM published states the haptic service used, the peak
# rendered force stayed within the device's limit and the tissue never
# received more than that.
#   run_local_test.sh BUILD_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build="${1:?usage: run_local_test.sh BUILD_DIR}"
out=$(mktemp /tmp/fahr-e2e-XXXXXX.txt)
trap 'rm -f "$out"' EXIT

# run_local.sh enters a namespace itself as root; the flag says this one
# already is, so the test's bound (FAHR_NETNS_TIMEOUT) covers the whole run.
status=0
FAHR_NETNS_TIMEOUT=100 FAHR_RUN_LOCAL_IN_NETNS=1 \
  "$repo/tests/run_in_netns.sh" bash "$repo/deployment/run_local.sh" "$build" \
  --dds cyclonedds --domain 77 --duration-s 8 >"$out" 2>&1 || status=$?
cat "$out"
if [ "$status" -ne 0 ]; then
  echo "FAIL: run_local.sh exited with $status"
  exit 1
fi

# A figure from the summary's "| name | value |" table.
figure() { awk -F'|' -v key="$1" '{ gsub(/^ +| +$/, "", $2) } $2 == key { gsub(/ /, "", $3); print $3; exit }' "$out"; }
# The ticks column of a service's row in the summary's first table.
ticks_of() { awk -F'|' -v key="$1" '{ gsub(/ /, "", $2) } $2 == key { gsub(/ /, "", $6); print $6; exit }' "$out"; }

fail=0
check() {  # check DESCRIPTION AWK-CONDITION
  if awk "BEGIN { exit !($2) }"; then echo "ok: $1"; else echo "FAIL: $1 ($2)"; fail=1; fi
}
commands=$(figure "ForceCommand samples")
limit=$(figure "device force limit (renderable, last) N")
peak=$(figure "peak rendered force N")
fem_ticks=$(ticks_of fem)
haptic_ticks=$(ticks_of haptic)
fem_states=$(sed -n 's/.*fahr_haptic_service: [0-9]* ticks on \([0-9]*\) FEM states.*/\1/p' "$out" | tail -n 1)
reaction=$(figure "peak tissue reaction N")
# The Touch X's peak force (services/device_gateway, the simulated device's
# model): the renderable force is at most this, less once it derates.
device_peak=7.9
check "the haptic service answered DevicePoses: ForceCommand samples ${commands:-none} > 0" "${commands:-0} > 0"
check "the haptic service reported ticks: ${haptic_ticks:-none} > 0" "${haptic_ticks:-0} > 0"
check "the FEM service reported steps: ${fem_ticks:-none} > 0" "${fem_ticks:-0} > 0"
check "the haptic service used FEM states: ${fem_states:-none} > 0" "${fem_states:-0} > 0"
check "the device's force limit was reported: ${limit:-none} N > 0" "${limit:-0} > 0"
check "peak rendered force ${peak:-none} N <= the device's peak ${device_peak} N" "${peak:-1e9} <= $device_peak + 1e-6"
# Force-aware: the tissue never receives more than the device can render
# (5 % for the one tick the FEM state lags).
check "peak tissue reaction ${reaction:-none} N <= 1.05 x ${device_peak} N" "${reaction:-1e9} <= 1.05 * $device_peak"
exit "$fail"
