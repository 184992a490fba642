#!/usr/bin/env bash
# A Fast-DDS-only station on one host with the Fast DDS discovery server
# (discovery: server in the lab file): fahr_lab up starts
# fast-discovery-server first, the services find each other through it, the
# station ends with the gateway's run. In a loopback-only namespace (root).
#
#   tests/lab/discovery_server.sh BUILD_DIR [SECONDS]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
seconds=${2:-6}
if [ -z "${FAHR_DS_TEST_IN_NETNS:-}" ]; then
  FAHR_DS_TEST_IN_NETNS=1 FAHR_NETNS_TIMEOUT=300 exec "$repo/tests/run_in_netns.sh" bash "$0" "$@"
fi
work=$(mktemp -d /tmp/fahr-ds-test-XXXXXX)
trap 'rm -rf "$work"' EXIT
cat >"$work/lab.yaml" <<EOF2
format_version: 1
hosts:
  - {name: this-pc, address: 127.0.0.1, interface: lo}
stations:
  - name: ds
    domain: 62
    scene: $repo/deployment/scenes/neonatal_intubation.yaml
    vendor: fastdds
    discovery: server
    discovery_server_host: this-pc
    duration_s: $seconds
    services:
      fem: {host: this-pc}
      haptic: {host: this-pc}
      device_gateway: {host: this-pc}
      summary: {host: this-pc}
EOF2
export FAHR_RUN_ROOT="$work/runs"
"$build/tools/lab/fahr_lab" check "$work/lab.yaml" | grep "discovery:"
timeout 240 "$build/tools/lab/fahr_lab" up "$work/lab.yaml" ds
run="$work/runs/ds"
grep -q "Server is running" "$run/discovery_server.log" || { echo "discovery_server: no server" >&2; exit 1; }
grep -q -- "-l 127.0.0.1 -p 11873\|11873" "$run/discovery_server.log" || true
poses=$(awk -F'|' '/DevicePose samples/ { gsub(/ /, "", $3); print $3 }' "$run/summary.log")
used=$(sed -n 's/.* on \([0-9]*\) FEM states.*/\1/p' "$run/haptic.log")
echo "discovery_server: summary heard ${poses:-0} DevicePoses; the haptic service used ${used:-0} FEM states"
[ "${poses:-0}" -gt 0 ] && [ "${used:-0}" -gt 0 ]
