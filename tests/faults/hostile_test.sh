#!/usr/bin/env bash
# Hostile samples: the station (FEM, haptic, gateway on the scripted
# intubation) runs in real time as separate processes while hostile_peer,
# a participant allowed on the domain (no DDS Security), floods every stream
# the services read (non-finite, huge, out-of-order, wrong-size and
# well-formed foreign samples) as fast as it can from one core held to a
# 25 % CPU quota, one second on and one second off. Checks:
#   - each service keeps its rate in the flood windows against the calm ones
#     in between (window_rates.py: the gateway's poses and the haptic
#     service's commands at 99 %, the FEM's states at 90 %);
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
scene="$repo/deployment/scenes/neonatal_intubation.yaml"
flags=(--dds "$vendor" --domain "$domain")
out=${FAHR_KEEP_HOSTILE:-$(mktemp -d /tmp/fahr-hostile-XXXXXX)}
mkdir -p "$out"
run_s=14
flood_s=12
gateway_exe="$build/services/device_gateway/fahr_device_gateway"
fem_exe="$build/services/fem/fahr_fem_service"
haptic_exe="$build/services/haptic/fahr_haptic_service"
hostile_exe="$build/tests/faults/hostile_peer"
probe_exe="$build/tests/faults/fault_probe"
for exe in "$gateway_exe" "$fem_exe" "$haptic_exe" "$hostile_exe" "$probe_exe"; do
  [ -x "$exe" ] || { echo "hostile_test: $exe is missing (build it)" >&2; exit 1; }
done
# The station at a high CFS weight, as in fault_test.sh: the test is about
# the intruder, not about other work on a shared machine.
nice_level=${FAHR_HOSTILE_NICE:--15}

# The intruder's 25 % of one core: a cgroup of its own (cpu_quota.sh).
source "$repo/tests/faults/cpu_quota.sh"

pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  quota_unmount
  [ -n "${FAHR_KEEP_HOSTILE:-}" ] || rm -rf "$out"
}
trap cleanup EXIT

wait_for() {  # wait_for LOG PATTERN TIMEOUT_S
  local deadline=$(( $(date +%s) + $3 ))
  until grep -q "$2" "$1" 2>/dev/null; do
    [ "$(date +%s)" -lt "$deadline" ] || { echo "hostile_test: '$2' not in $1 within $3 s" >&2; tail -n 20 "$1" >&2; return 1; }
    sleep 0.05
  done
}

quota_mount
quota_group intruder 25
echo "hostile_test: $vendor, domain $domain, a ${run_s} s run, files in $out"
nice -n "$nice_level" "$fem_exe" --scene "$scene" "${flags[@]}" --mode realtime --duration-s "$((run_s + 30))" >"$out/fem.log" 2>&1 &
fem=$!; pids+=("$fem")
nice -n "$nice_level" "$haptic_exe" --scene "$scene" "${flags[@]}" --mode realtime --duration-s "$((run_s + 30))" >"$out/haptic.log" 2>&1 &
haptic=$!; pids+=("$haptic")
wait_for "$out/fem.log" "Hz, realtime" 180
wait_for "$out/haptic.log" "fahr_haptic_service: ready" 180
nice -n "$nice_level" "$probe_exe" "${flags[@]}" --states --duration-s "$((run_s + 30))" --out "$out/probe.txt" >"$out/probe.log" 2>&1 &
probe=$!; pids+=("$probe")
sleep 1  # the probe's readers match before the first DevicePose
nice -n "$nice_level" "$gateway_exe" "${flags[@]}" --backend simulated --script intubation --duration-s "$run_s" \
  >"$out/gateway.log" 2>&1 &
gateway=$!; pids+=("$gateway")
sleep 1
"$hostile_exe" "${flags[@]}" --seconds "$flood_s" --on-off-s 1 >"$out/hostile.log" 2>&1 &
hostile=$!; pids+=("$hostile")
quota_put intruder "$hostile"
taskset -p -c 0 "$hostile" >/dev/null
wait "$hostile" || { echo "hostile_test: hostile_peer failed" >&2; cat "$out/hostile.log" >&2; exit 1; }
wait "$gateway" || { echo "hostile_test: the gateway exited with $?" >&2; exit 1; }
for p in "$haptic" "$fem" "$probe"; do kill -INT "$p" 2>/dev/null || true; done
wait "$haptic" || { echo "hostile_test: the haptic service exited with $?" >&2; exit 1; }
wait "$fem" || { echo "hostile_test: the FEM exited with $?" >&2; exit 1; }
wait "$probe" || true
pids=()

num() {  # num FILE SED_EXPRESSION: the last match
  sed -n "$2" "$1" | tail -n 1
}
status=0
check() {  # check DESCRIPTION COMMAND...
  local what=$1; shift
  if "$@"; then echo "  ok    $what"; else echo "  FAIL  $what"; status=1; fi
}
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a >= b) }'; }

grep -h "^hostile: wrote" "$out/hostile.log" | sed 's/^/hostile_test: /'
grep -h "refused" "$out/gateway.log" "$out/haptic.log" "$out/fem.log" | sed 's/^/hostile_test: /'
echo "hostile_test: rates, flood windows against the calm ones between them"
# The floods from hostile_peer's "hostile: on <ns> <ns>" lines; the calm
# windows are the rests between them.
awk '$1 == "hostile:" && $2 == "on" { if (n++) print "calm", last, $3; print "flood", $3, $4; last = $4 }' \
  "$out/hostile.log" >"$out/windows.txt"
python3 "$repo/tests/faults/window_rates.py" "$out/probe.txt" "$out/windows.txt" \
  flood:gateway:0.99 flood:haptic:0.99 flood:fem:0.90 | tee "$out/rates.md" || status=1

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
