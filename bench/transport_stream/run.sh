#!/usr/bin/env bash
# The three roles of fahr_transport_stream on one vendor mix, inside a
# loopback-only network namespace (tests/run_in_netns.sh, root), then the
# namespace's UDP receive-buffer drops (nstat).
#
#   bench/transport_stream/run.sh BUILD_DIR GATEWAY_V HAPTIC_V FEM_V [SECONDS] [STATE_KIB] [-- FLAGS]
#
# FLAGS go to every role (e.g. --dds-profile FILE).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
if [ -z "${FAHR_STREAM_IN_NETNS:-}" ]; then
  FAHR_STREAM_IN_NETNS=1 FAHR_NETNS_TIMEOUT=300 exec "$repo/tests/run_in_netns.sh" bash "$0" "$@"
fi
build=$1 gateway=$2 haptic=$3 fem=$4
seconds=${5:-10} kib=${6:-250}
shift $(($# < 6 ? $# : 6))
[ "${1:-}" = "--" ] && shift
exe="$build/bench/transport_stream/fahr_transport_stream"
logs=$(mktemp -d /tmp/fahr-stream-XXXXXX)
nstat -n >/dev/null 2>&1 || true
common=(--domain 7 --seconds "$seconds" --state-kb "$kib" "$@")
"$exe" --role fem --dds "$fem" "${common[@]}" >"$logs/fem.log" 2>&1 &
"$exe" --role haptic --dds "$haptic" "${common[@]}" >"$logs/haptic.log" 2>&1 &
"$exe" --role gateway --dds "$gateway" "${common[@]}" >"$logs/gateway.log" 2>&1 &
status=0
wait -n || status=$?
wait -n || status=$?
wait -n || status=$?
echo "gateway $gateway, haptic $haptic, fem $fem, DeformationState ${kib} KiB at 200 Hz, ${seconds} s"
cat "$logs/gateway.log" "$logs/haptic.log" "$logs/fem.log"
drops=$(nstat -a 2>/dev/null | awk '$1 == "UdpRcvbufErrors" { print $2 }')
echo "stream: UDP receive-buffer drops ${drops:-0}"
rm -rf "$logs"
exit "$status"
