#!/usr/bin/env bash
# Hostile samples: the station (FEM, haptic, gateway on the scripted
# intubation) runs in real time as separate processes while hostile_peer,
# a participant allowed on the domain (no DDS Security), floods every stream
# the services read (non-finite, huge, out-of-order, wrong-size and
# well-formed foreign samples) as fast as it can from one core held to a
# 25 % CPU quota, one second on and one second off. Checks:
#   - each service keeps its rate in the flood windows against the calm ones
#     in between (window_rates.py: the gateway's poses at 98 %, the haptic
#     service's commands at 90 %; the goal is 99 %, not met: the intruder's
#     samples are decoded before they are refused, and that costs the haptic
#     service 4-5 % of its ticks, 0.953 on a calm machine, 0.955-0.959 at
#     load 7.
#     The FEM's states at half, pooled over all windows: it misses its rate
#     under the blade (45-50 states a second here, with steps of hundreds of
#     ms and divergence resets), so one 0.8 s window's rate says more about
#     its own stalls than about the flood (window medians 0.28-1.34 x their
#     calm neighbours); pooled, the flood windows gave 1.10-1.33 x the calm ones,
#     and a FEM the flood stalled would publish nothing);
#     The rates are judged when the machine keeps the station in real time
#     (the gateway's calm windows at 98 % of its 1 kHz); on a VM whose host
#     steals its CPU they are printed, not judged (docs/design/faults.md);
#   - no hostile sample is used: the haptic service ticks only on the
#     gateway's poses and the gateway accepts only the haptic service's
#     commands (its intruder pushes 2 N);
#   - each kind is refused and counted, and said at the end of each service.
#
#   hostile_test.sh BUILD_DIR VENDOR
#
# Runs inside a loopback-only network namespace (tests/run_in_netns.sh).
# FAHR_KEEP_HOSTILE=DIR keeps the logs there.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: hostile_test.sh BUILD_DIR VENDOR}" && pwd)
vendor=${2:?usage: hostile_test.sh BUILD_DIR VENDOR}
domain=${FAHR_HOSTILE_DOMAIN:-62}
out=${FAHR_KEEP_HOSTILE:-$(mktemp -d /tmp/fahr-hostile-XXXXXX)}
FAHR_KEEP=${FAHR_KEEP_HOSTILE:-}
name=hostile_test
run_s=14
flood_s=12
hostile_exe="$build/tests/faults/hostile_peer"
[ -x "$hostile_exe" ] || { echo "hostile_test: $hostile_exe is missing (build it)" >&2; exit 1; }
source "$repo/tests/faults/station.sh"

# The intruder: 25 % of core 0.
quota_mount
quota_group intruder 25
station_start
sleep 1
"$hostile_exe" "${flags[@]}" --seconds "$flood_s" --on-off-s 1 >"$out/hostile.log" 2>&1 &
hostile=$!; pids+=("$hostile")
quota_put intruder "$hostile"
taskset -p -c 0 "$hostile" >/dev/null
wait "$hostile" || { echo "hostile_test: hostile_peer failed" >&2; cat "$out/hostile.log" >&2; exit 1; }
station_stop

num() {  # num FILE SED_EXPRESSION: the last match
  sed -n "$2" "$1" | tail -n 1
}
grep -h "^hostile: wrote" "$out/hostile.log" | sed 's/^/hostile_test: /'
grep -h "refused" "$out/gateway.log" "$out/haptic.log" "$out/fem.log" | sed 's/^/hostile_test: /'
echo "hostile_test: rates, flood windows against the calm ones between them"
# The floods from hostile_peer's "hostile: on <ns> <ns>" lines; the calm
# windows are the rests between them.
awk '$1 == "hostile:" && $2 == "on" { if (n++) print "calm", last, $3; print "flood", $3, $4; last = $4 }' \
  "$out/hostile.log" >"$out/windows.txt"
python3 "$repo/tests/faults/window_rates.py" --real-time gateway:1000:0.98 "$out/probe.txt" "$out/windows.txt" \
  flood:gateway:0.98 flood:haptic:0.90 flood:fem:0.50:pooled | tee "$out/rates.md" || status=1

echo "hostile_test: checks"
gw_ticks=$(num "$out/gateway.log" 's/.*device_gateway: ticks \([0-9]*\),.*/\1/p')
accepted=$(num "$out/gateway.log" 's/.*commands accepted \([0-9]*\),.*/\1/p')
hp_ticks=$(num "$out/haptic.log" 's/.* over \([0-9]*\) ticks;.*/\1/p')
hp_poses=$(num "$out/haptic.log" 's/.*DevicePoses received \([0-9]*\),.*/\1/p')
refusals() {  # refusals FILE STREAM: foreign + out of order + invalid of that stream's line part
  sed -n "s/.*$2: foreign \([0-9]*\), out of order \([0-9]*\), invalid \([0-9]*\),.*/\1 \2 \3/p" "$1" |
    tail -n 1 | awk '{ print $1 + $2 + $3 }'
}
check "the haptic service ticked only on the gateway's poses (${hp_poses:-?} received, gateway ticks ${gw_ticks:-?})" \
  ge "${gw_ticks:-0}" "${hp_poses:-1}"
check "the gateway accepted only the haptic service's commands (${accepted:-?} accepted, haptic ticks ${hp_ticks:-?})" \
  ge "${hp_ticks:-0}" "${accepted:-1}"
written() { sed -n "s/.*$1 \([0-9]*\)[,)].*/\1/p" "$out/hostile.log" | tail -n 1; }
for pair in "gateway.log:refused ForceCommands:ForceCommand" "haptic.log:refused DevicePoses:DevicePose" \
  "haptic.log:DeformationStates:DeformationState" "fem.log:refused ContactSets:ContactSet"; do
  IFS=: read -r log stream kind <<<"$pair"
  n=$(refusals "$out/$log" "$stream"); w=$(written "$kind")
  # Best effort: a flooded reader may lose some of the intruder's samples in
  # transport, never use one: at least half of them counted as refused.
  check "$kind: ${n:-0} of the intruder's ${w:-?} refused and counted" ge "${n:-0}" "$(( ${w:-2} / 2 ))"
done
exit "$status"
