#!/usr/bin/env bash
# fahr_lab's supervision with restart: true, on one host (a loopback-only
# namespace, root): the FEM service killed twice in a row is restarted after
# its back-off (0.5 s, then 1 s), the haptic service takes the new FEM up
# (a new writer), and the station ends with the gateway's run as usual.
#
#   tests/lab/restart.sh BUILD_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
if [ -z "${FAHR_RESTART_TEST_IN_NETNS:-}" ]; then
  FAHR_RESTART_TEST_IN_NETNS=1 FAHR_NETNS_TIMEOUT=300 exec "$repo/tests/run_in_netns.sh" bash "$0" "$@"
fi
work=$(mktemp -d /tmp/fahr-restart-test-XXXXXX)
lab_pid=""
cleanup() {
  [ -n "$lab_pid" ] && kill "$lab_pid" 2>/dev/null && wait "$lab_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
cat >"$work/lab.yaml" <<EOF2
format_version: 1
hosts:
  - {name: this-pc, address: 127.0.0.1, interface: lo}
stations:
  - name: rs
    domain: 63
    scene: $repo/deployment/scenes/neonatal_intubation.yaml
    vendor: cyclonedds
    restart: true
    duration_s: 40
    services:
      fem: {host: this-pc}
      haptic: {host: this-pc}
      device_gateway: {host: this-pc}
EOF2
export FAHR_RUN_ROOT="$work/runs"
run="$work/runs/rs"
timeout 280 "$build/tools/lab/fahr_lab" up "$work/lab.yaml" rs >"$work/lab.log" 2>&1 &
lab_pid=$!

# Waits until FILE has PATTERN (grep -E), at most SECONDS.
wait_for() {
  local file=$1 pattern=$2 until=$((SECONDS + $3)) seconds=$3
  while [ "$SECONDS" -lt "$until" ]; do
    grep -qE "$pattern" "$file" 2>/dev/null && return 0
    sleep 0.1
  done
  echo "restart_test: no '$pattern' in $(basename "$file") within $seconds s" >&2
  cat "$work/lab.log" >&2
  return 1
}
fem_pid() { sed -n 's/^service fem pid \([0-9]*\) .*/\1/p' "$run/status"; }

wait_for "$run/status" "^service device_gateway pid [0-9]+ state running" 120
sleep 2
kill -KILL "$(fem_pid)"
wait_for "$work/lab.log" "fem restarted \(pid [0-9]+, restart 1\)" 20
# The restarted FEM's pid from fahr_lab's own line: it writes the status
# file after that line, so the file may still name the dead one.
kill -KILL "$(sed -n 's/.*fem restarted (pid \([0-9]*\), restart 1).*/\1/p' "$work/lab.log" | tail -n 1)"
wait_for "$work/lab.log" "fem restarted \(pid [0-9]+, restart 2\)" 20
wait "$lab_pid" || true
lab_pid=""
cat "$work/lab.log"
grep -q "fem restarting in 0.5 s (death 1 in a row" "$work/lab.log"
grep -q "fem restarting in 1.0 s (death 2 in a row" "$work/lab.log"
grep -q "stopping: the gateway's run of 40 s ended" "$work/lab.log" ||
  { echo "restart_test: the station did not end with the gateway's run" >&2; exit 1; }
# The haptic service took the restarted FEM up (a new writer: the resume slew).
grep -q "FEM back\|new FEM" "$run/haptic.log" ||
  { echo "restart_test: the haptic service never took the restarted FEM up" >&2; exit 1; }
echo "restart_test: the FEM was restarted twice with its back-off and the station ran to its end"
