#!/usr/bin/env bash
# A station across three "hosts" on one machine: three network namespaces
# joined by veth pairs to a bridge in a fourth, multicast dropped by nftables
# in each, every service started by fahr_lab up from one lab file:
#   h1 (10.77.0.1): device gateway + haptic
#   h2 (10.77.0.2): FEM
#   h3 (10.77.0.3): logger (on the haptic service's vendor, so the
#                   FEM-to-recorder latency is the FEM-to-haptic vendor pair's)
#                   + run summary, and the probes
# A second station of the lab shares the domain under another partition; a
# probe in its partition must match nothing of the running station. Another
# probe in the station's partition measures discovery: a participant joining
# the running station until every reader has matched.
#
#   tests/lab/three_hosts.sh BUILD_DIR GATEWAY_V HAPTIC_V FEM_V SECONDS [REPORT.md]
#       [--relay] [--link hA-hB:delay_ms=..,jitter_ms=..,loss=..]... [--gateway-apart]
#       [--nice N] [--rt] [--clock-offset hN=MS]
#
# --relay, --link: fahr_udp_relay (tests/lab/udp_relay.cpp) replaces the
# bridge and switches every frame between the hosts; a --link impairs one
# pair of hosts (delay, jitter, loss; the relay's options), the others pass
# at once. --gateway-apart: the gateway runs on h3 with the observers, away
# from its haptic service (the recorder then hears the ForceCommands where
# the gateway does). --nice N runs the stations at nice -N (ahead of other
# work on a shared machine), --rt gives the gateway's and the haptic
# service's 1 kHz ticks SCHED_FIFO (the lab file's rt_priority).
# --clock-offset h2=40: every process of that namespace sees a wall clock
# 40 ms ahead (FAHR_TEST_CLOCK_OFFSET_MS, the clock's test hook), as an
# unsynchronised host would; the cross-host figures must stay honest: the
# recording's latencies from that host, corrected by the offset fahr_lab's
# clock echoes measured, within their error, and the uncorrected ones
# visibly off.
#
# Needs root (it creates namespaces); anything it cannot do fails the test.
# Everything it creates is removed on exit; each step is bounded in time.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
gateway_v=$2 haptic_v=$3 fem_v=$4 seconds=$5
shift 5
report=""
if [ $# -gt 0 ] && [[ "$1" != --* ]]; then report=$1; shift; fi
use_relay="" links=() gateway_host=h1 nice_prefix=() rt_gateway=0 rt_haptic=0
offset_host="" offset_ms=0
while [ $# -gt 0 ]; do
  case "$1" in
    --relay) use_relay=1; shift ;;
    --link) use_relay=1; links+=(--link "$2"); shift 2 ;;
    --gateway-apart) gateway_host=h3; shift ;;
    --nice) [ "$2" != 0 ] && nice_prefix=(nice -n "-$2"); shift 2 ;;
    --rt) rt_gateway=40 rt_haptic=39; shift ;;
    --clock-offset) offset_host=${2%%=*} offset_ms=${2#*=}; shift 2 ;;
    *) echo "three_hosts: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
relay="$build/tests/lab/fahr_udp_relay"
if [ -n "$use_relay" ] && [ ! -x "$relay" ]; then
  echo "three_hosts: $relay is missing (build fahr_udp_relay)" >&2
  exit 1
fi
lab_tool="$build/tools/lab/fahr_lab"
probe="$build/tools/dds_check/fahr_dds_check"
for exe in "$lab_tool" "$probe"; do
  [ -x "$exe" ] || { echo "three_hosts: $exe is missing (build fahr_lab fahr_dds_check and the services)" >&2; exit 1; }
done
if [ "$(id -u)" -ne 0 ]; then
  echo "three_hosts: needs root to create network namespaces" >&2
  exit 1
fi
command -v nft >/dev/null || { echo "three_hosts: nft (nftables) is missing" >&2; exit 1; }

tag="fl$$"
sw="$tag-sw"
hosts=(h1 h2 h3)
work=$(mktemp -d /tmp/fahr-lab-test-XXXXXX)
relay_pid=""
cleanup() {
  set +e
  [ -n "$relay_pid" ] && kill -TERM "$relay_pid" 2>/dev/null
  for h in "${hosts[@]}"; do
    if ip netns list | grep -q "^$tag-$h\b"; then
      # Stop whatever still runs in the namespace, then remove it.
      ip netns pids "$tag-$h" 2>/dev/null | xargs -r kill -TERM 2>/dev/null
      sleep 0.5
      ip netns pids "$tag-$h" 2>/dev/null | xargs -r kill -KILL 2>/dev/null
      ip netns del "$tag-$h"
    fi
  done
  ip netns del "$sw" 2>/dev/null
  if [ -z "${FAHR_LAB_TEST_KEEP:-}" ]; then rm -rf "$work"; else echo "three_hosts: kept $work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# The network: a bridge (or the relay) in its own namespace, one veth pair
# per host.
ip netns add "$sw"
if [ -z "$use_relay" ]; then
  ip -n "$sw" link add br0 type bridge
  ip -n "$sw" link set br0 up
fi
relay_ports=()
i=0
for h in "${hosts[@]}"; do
  i=$((i + 1))
  ns="$tag-$h"
  ip netns add "$ns"
  ip -n "$ns" link set lo up
  ip link add "$tag$h" type veth peer name lab0 netns "$ns"
  ip link set "$tag$h" netns "$sw"
  if [ -z "$use_relay" ]; then
    ip -n "$sw" link set "$tag$h" master br0 up
  else
    ip -n "$sw" link set "$tag$h" up
    relay_ports+=(--port "$h=$tag$h")
  fi
  ip -n "$ns" addr add "10.77.0.$i/24" dev lab0
  ip -n "$ns" link set lab0 up
  # Multicast dropped both ways, counted.
  ip netns exec "$ns" nft -f - <<EOF
table inet fahr_lab_test {
  chain in { type filter hook input priority 0; ip daddr 224.0.0.0/4 counter drop; meta pkttype multicast counter drop; }
  chain out { type filter hook output priority 0; ip daddr 224.0.0.0/4 counter drop; }
}
EOF
done

if [ -n "$use_relay" ]; then
  ip netns exec "$sw" timeout $((seconds + 600)) "$relay" "${relay_ports[@]}" "${links[@]}" \
    --seed "${FAHR_LAB_RELAY_SEED:-1}" --rt-priority 20 >"$work/relay.out" 2>&1 &
  relay_pid=$!
  for _ in $(seq 200); do grep -q ready "$work/relay.out" 2>/dev/null && break; sleep 0.05; done
  grep -q ready "$work/relay.out" || { echo "three_hosts: the relay did not start:" >&2; cat "$work/relay.out" >&2; exit 1; }
  echo "three_hosts: relay: $(grep ready "$work/relay.out")"
fi

# The lab file.
lab="$work/lab.yaml"
cat >"$lab" <<EOF
format_version: 1
lab:
  name: three-namespaces
  clock_sync: none
hosts:
  - {name: h1, address: 10.77.0.1, interface: lab0}
  - {name: h2, address: 10.77.0.2, interface: lab0}
  - {name: h3, address: 10.77.0.3, interface: lab0}
stations:
  - name: bed-1
    domain: 17
    partition: bed-1
    scene: $repo/deployment/scenes/neonatal_intubation.yaml
    duration_s: $seconds
    services:
      device_gateway: {host: $gateway_host, vendor: $gateway_v, rt_priority: $rt_gateway}
      haptic: {host: h1, vendor: $haptic_v, rt_priority: $rt_haptic}
      fem: {host: h2, vendor: $fem_v}
      logger: {host: h3, vendor: $haptic_v, args: [--decimate, fahr/DeformationState=10]}
      summary: {host: h3, vendor: cyclonedds}
  - name: bed-2
    domain: 17
    partition: bed-2
    scene: $repo/deployment/scenes/neonatal_intubation.yaml
    services:
      device_gateway: {host: h1}
      haptic: {host: h1}
      fem: {host: h2}
EOF
echo "three_hosts: lab file:"
sed 's/^/  /' "$lab"
echo "three_hosts: plan:"
"$lab_tool" check "$lab" | sed 's/^/  /'

run_root="$work/runs"
in_ns() { local h=$1; shift; ip netns exec "$tag-$h" env FAHR_RUN_ROOT="$run_root/$h" "$@"; }
up_ns() {
  local h=$1; shift
  local offset=0
  [ "$h" = "$offset_host" ] && offset=$offset_ms
  in_ns "$h" env FAHR_TEST_CLOCK_OFFSET_MS="$offset" "${nice_prefix[@]}" "$@"
}
# For investigating: run a command with the network and the lab file in
# place ($FAHR_LAB_TEST_DEBUG, given tag, lab and work folder), then clean up.
if [ -n "${FAHR_LAB_TEST_DEBUG:-}" ]; then
  "$FAHR_LAB_TEST_DEBUG" "$tag" "$lab" "$work" || true
  exit 0
fi
# The observers first, then the FEM, then the haptic side (its gateway's
# script starts at its first tick); the first two in the background.
# With the gateway apart, h3 holds it: h1 (the haptic service) comes up
# detached before it, and h3's station ends with the gateway's run.
first=h3 last=h1
[ "$gateway_host" = h3 ] && first=h1 last=h3
up_ns $first timeout 300 "$lab_tool" up "$lab" bed-1 --detach
up_ns h2 timeout 300 "$lab_tool" up "$lab" bed-1 --detach
started=$(date +%s.%N)
status=0
up_ns $last timeout $((seconds + 300)) "$lab_tool" up "$lab" bed-1 >"$work/h1.out" 2>&1 &
h1_pid=$!
# Wait until the gateway runs, then probe from h3 while the station runs.
for _ in $(seq 3000); do
  grep -q "station bed-1 running" "$work/h1.out" 2>/dev/null && break
  kill -0 "$h1_pid" 2>/dev/null || break
  sleep 0.1
done
grep -q "station bed-1 running" "$work/h1.out" || { echo "three_hosts: h1 did not start:" >&2; cat "$work/h1.out" >&2; exit 1; }
probe_s=$(awk -v s="$seconds" 'BEGIN { p = s / 3; if (p > 5) p = 5; if (p < 3) p = 3; print p }')
tools="$run_root/h3/bed-1/config"
in_ns h3 env FAHR_PARTITION=bed-1 timeout 60 "$probe" --dds cyclonedds --domain 17 \
  --dds-profile "$tools/tool_cyclonedds.xml" --station --listen-s "$probe_s" >"$work/probe_same.out" 2>&1 || status=1
# Station bed-2's partition on the same domain, with bed-1's peers.
in_ns h3 "$lab_tool" config "$lab" bed-2 h3 "$work/bed-2" >/dev/null
in_ns h3 env FAHR_PARTITION=bed-2 timeout 60 "$probe" --dds fastdds --domain 17 \
  --dds-profile "$work/bed-2/tool_fastdds.xml" --station --listen-s "$probe_s" >"$work/probe_other.out" 2>&1 || status=1
wait "$h1_pid" || { status=1; echo "three_hosts: h1's station ended with an error:" >&2; cat "$work/h1.out" >&2; }
ended=$(date +%s.%N)
in_ns h2 timeout 60 "$lab_tool" down bed-1 >"$work/h2.down" 2>&1 || status=1
in_ns $first timeout 60 "$lab_tool" down bed-1 >"$work/$first.down" 2>&1 || status=1
relay_books=""
if [ -n "$relay_pid" ]; then
  kill -TERM "$relay_pid" 2>/dev/null
  wait "$relay_pid" || { status=1; echo "three_hosts: the relay ended with an error" >&2; }
  relay_pid=""
  relay_books=$(grep -v ready "$work/relay.out" | sed 's/^fahr_udp_relay: //')
fi

r1="$run_root/h1/bed-1" r2="$run_root/h2/bed-1" r3="$run_root/h3/bed-1"
rg="$run_root/$gateway_host/bed-1"
for f in "$r1/fahr_lab.log" "$r2/fahr_lab.log" "$r3/fahr_lab.log"; do
  if grep -q "died" "$f"; then status=1; echo "three_hosts: a service died:" >&2; grep died "$f" >&2; fi
done
drops=""
for h in "${hosts[@]}"; do
  n=$(ip netns exec "$tag-$h" nft list table inet fahr_lab_test | grep -o 'packets [0-9]*' | awk '{ s += $2 } END { print s + 0 }')
  drops="$drops $h:$n"
done

discovery=$(grep -o "every reader matched in [0-9.]* s" "$work/probe_same.out" | awk '{ print $5 }')
other=$(grep -o "endpoints matched: [0-9]*, samples: [0-9]*" "$work/probe_other.out" || true)
summary=$(sed -n '/^## fahr run summary/,$p' "$r3/summary.log")
fem_line=$(grep "steps, stale contact sets" "$r2/fem.log" || true)
haptic_line=$(grep "ticks on .* FEM states" "$r1/haptic.log" || true)
pose_line=$(grep "DevicePoses received" "$r1/haptic.log" || true)
gateway_line=$(grep "^device_gateway: ticks" "$rg/device_gateway.log" || true)
logger_table=$(grep "^fahr_logger: " "$r3/logger.log" | grep -v "recording to\|writers matched" || true)
# The whole run's latencies from the recording (the namespaces share one
# kernel clock, so receive minus source time is a one-way latency): motion
# to force over every answered pose, each topic from its writer's host to
# the recorder's, and the loss books (gaps before the recorder matched a
# writer are discovery, not loss).
trace=""
if [ -x "$build/tools/trace/fahr_trace" ]; then
  trace=$("$build/tools/trace/fahr_trace" "$r3/bed-1.mcap" -o "$work/trace.json" --clock "$r3/clock.txt" 2>&1 |
    sed -n '/^motion-to-force/,/^DevicePose period/p;/^loss per writer/,$p' | grep -v "^DevicePose period" || true)
fi

raw_trace=""
if [ -n "$offset_host" ] && [ -x "$build/tools/trace/fahr_trace" ]; then
  raw_trace=$("$build/tools/trace/fahr_trace" "$r3/bed-1.mcap" -o "$work/trace_raw.json" 2>&1 || true)
fi
{
  echo "### gateway $gateway_v, haptic $haptic_v, FEM $fem_v: ${seconds} s across three namespaces"
  echo
  if [ -n "$use_relay" ]; then
    echo "- network: fahr_udp_relay ($(echo "${links[@]:-}" | sed 's/--link //g; s/^ *$/no impairment/')); gateway on $gateway_host"
    echo "- relay: $(echo "$relay_books" | paste -sd';' | sed 's/;/; /g')"
  fi
  echo "- discovery (a participant joining the running station, every reader matched): ${discovery:-not complete} s"
  echo "- station bed-2 (same domain, partition bed-2) probe: ${other:-no result}"
  echo "- multicast packets dropped by nftables per host:$drops"
  echo "- FEM: ${fem_line#fahr_fem_service: }"
  echo "- haptic: ${haptic_line#fahr_haptic_service: }; ${pose_line#fahr_haptic_service: }"
  echo "- gateway: ${gateway_line#device_gateway: }"
  echo "- clocks against h3's (fahr_lab's echoes; host, offset ms, error ms): $(awk '/^host/ { printf "%s%s %s +- %s", sep, $2, $5, $7; sep = "; " }' "$r3/clock.txt" 2>/dev/null)"
  if [ -n "$offset_host" ]; then
    echo "- $offset_host's clock offset by the test hook: $offset_ms ms; fahr_trace without --clock: $(echo "$raw_trace" | awk '$1 == "fahr/DeformationState" && $3 ~ /[.]/ { print "DeformationState p50 " $3 " ms" }')"
  fi
  echo
  echo "$summary"
  echo
  if [ -n "$trace" ]; then
    echo "From the recording (fahr_trace --clock; FEM on h2, gateway on $gateway_host, haptic on h1, recorder on h3 on $haptic_v):"
    echo
    echo '```'
    echo "$trace"
    echo '```'
  else
    echo "Recording, per writer (sent = recorded + gaps + drops + skipped):"
    echo
    echo '```'
    echo "$logger_table"
    echo '```'
  fi
} >"$work/report.md"
cat "$work/report.md"
[ -n "$report" ] && cat "$work/report.md" >>"$report"

# What must hold.
fail() { echo "three_hosts: FAIL: $*" >&2; status=1; }
[ -n "$discovery" ] || fail "the probe's readers did not all match (discovery)"
if [ -n "$discovery" ] && awk -v d="$discovery" 'BEGIN { exit !(d > 3.0) }'; then
  fail "discovery took $discovery s (> 3 s)"
fi
[ "$other" = "endpoints matched: 0, samples: 0" ] || fail "station bed-2's probe saw bed-1: '$other'"
[ -n "$fem_line" ] || fail "no FEM report"
used=$(echo "$haptic_line" | sed -n 's/.* on \([0-9]*\) FEM states.*/\1/p')
[ "${used:-0}" -gt 0 ] || fail "the haptic service used no FEM state from the other namespace"
poses=$(echo "$summary" | awk -F'|' '/DevicePose samples/ { gsub(/ /, "", $3); print $3 }')
[ "${poses:-0}" -gt 0 ] || fail "the summary on h3 heard no DevicePose"
if [ -n "$offset_host" ]; then
  # The FEM's states from h2 to the recorder on h3: under 10 ms once
  # corrected (within the measured error), about -offset as stamped.
  corrected=$(echo "$trace" | awk '$1 == "fahr/DeformationState" && $3 ~ /[.]/ { print $3, $7 }')
  raw=$(echo "$raw_trace" | awk '$1 == "fahr/DeformationState" && $3 ~ /[.]/ { print $3 }')
  measured=$(awk -v h="$offset_host" '$1 == "host" && $2 == h { print $5, $7 }' "$r3/clock.txt")
  echo "three_hosts: clock offset $offset_ms ms on $offset_host; measured (offset, error): ${measured:-none}; DeformationState p50 corrected (p50, +-): ${corrected:-none}, as stamped: ${raw:-none}"
  awk -v m="${measured:-x}" -v want="$offset_ms" 'BEGIN { split(m, a, " "); exit !(m != "x" && a[2] >= 0 && a[2] < 5 && a[1] - want < a[2] + 0.5 && want - a[1] < a[2] + 0.5) }' ||
    fail "the echoes measured $offset_host's clock at '${measured:-nothing}' for an offset of $offset_ms ms"
  awk -v c="${corrected:-x}" 'BEGIN { split(c, a, " "); exit !(c != "x" && a[1] > -a[2] - 0.5 && a[1] < 10) }' ||
    fail "DeformationState latency printed as '${corrected:-nothing}' (p50, +-) with $offset_host's clock off"
  awk -v r="${raw:-x}" -v want="$offset_ms" 'BEGIN { exit !(r != "x" && (r + want < 10 && r + want > -10)) }' ||
    fail "as stamped, the DeformationState latency is '${raw:-nothing}' ms: the test hook did not offset $offset_host's clock by $offset_ms ms"
  # No state is used before it was written: the youngest age (from each
  # recorded state's own write stamp) is not below zero by more than the
  # clocks' error and a millisecond; as stamped it would be about -offset.
  age=$(echo "$trace" | sed -n 's/.*FEM state age at use: *n [0-9]*  min \([-0-9.]*\) ms.*clocks: +-\([0-9.]*\) ms.*/\1 \2/p')
  awk -v a="${age:-x}" 'BEGIN { split(a, v, " "); exit !(a != "x" && v[1] > -v[2] - 1) }' ||
    fail "FEM state age (youngest, +-) '${age:-not printed}' ms with $offset_host's clock off"
fi
grep -q "stopped (the gateway's run" "$rg/fahr_lab.log" 2>/dev/null || grep -q "station bed-1 stopped" "$work/h1.out" ||
  fail "h1's station did not end with the gateway's run"
echo "three_hosts: wall time $(awk -v a="$started" -v b="$ended" 'BEGIN { printf "%.1f", b - a }') s, status $status"
exit "$status"
