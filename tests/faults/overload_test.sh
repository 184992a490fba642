#!/usr/bin/env bash
# Overload: the station (FEM, haptic, gateway on the scripted intubation)
# runs in real time as separate processes while one service at a time is
# held to 5 % of a core by a cgroup (cpu_quota.sh), so its steps or ticks
# come late: the FEM for 3 s, then, after 3 s calm, the haptic service for
# 3 s. Checks, from fault_probe's record (window_rates.py, each window
# against the calm ones of the same run):
#   - while the FEM is slow, the gateway's poses and the haptic service's
#     commands keep 99 % of their calm rate (nothing waits for the FEM);
#   - while the haptic service is slow, the gateway's poses keep 99 % and
#     the FEM's states 90 % (nothing waits for the haptic service);
#   - the late one is reported: the haptic service says the FEM lost, the
#     gateway counts the haptic service's silences.
#
#   overload_test.sh BUILD_DIR VENDOR
#
# Runs inside a loopback-only network namespace (tests/run_in_netns.sh).
# FAHR_KEEP_OVERLOAD=DIR keeps the logs there.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: overload_test.sh BUILD_DIR VENDOR}" && pwd)
vendor=${2:?usage: overload_test.sh BUILD_DIR VENDOR}
domain=${FAHR_OVERLOAD_DOMAIN:-63}
scene="$repo/deployment/scenes/neonatal_intubation.yaml"
flags=(--dds "$vendor" --domain "$domain")
out=${FAHR_KEEP_OVERLOAD:-$(mktemp -d /tmp/fahr-overload-XXXXXX)}
mkdir -p "$out"
run_s=16
gateway_exe="$build/services/device_gateway/fahr_device_gateway"
fem_exe="$build/services/fem/fahr_fem_service"
haptic_exe="$build/services/haptic/fahr_haptic_service"
probe_exe="$build/tests/faults/fault_probe"
for exe in "$gateway_exe" "$fem_exe" "$haptic_exe" "$probe_exe"; do
  [ -x "$exe" ] || { echo "overload_test: $exe is missing (build it)" >&2; exit 1; }
done
nice_level=${FAHR_OVERLOAD_NICE:--15}
source "$repo/tests/faults/cpu_quota.sh"

pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  quota_unmount
  [ -n "${FAHR_KEEP_OVERLOAD:-}" ] || rm -rf "$out"
}
trap cleanup EXIT
wait_for() {  # wait_for LOG PATTERN TIMEOUT_S
  local deadline=$(( $(date +%s) + $3 ))
  until grep -q "$2" "$1" 2>/dev/null; do
    [ "$(date +%s)" -lt "$deadline" ] || { echo "overload_test: '$2' not in $1 within $3 s" >&2; tail -n 20 "$1" >&2; return 1; }
    sleep 0.05
  done
}

quota_mount
quota_group slow 5
echo "overload_test: $vendor, domain $domain, a ${run_s} s run, files in $out"
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
now() { date +%s%N; }
: >"$out/windows.txt"
window() {  # window LABEL SECONDS [PID_TO_SLOW]
  local from; from=$(now)
  [ -z "${3:-}" ] || quota_put slow "$3"
  sleep "$2"
  [ -z "${3:-}" ] || quota_release "$3"
  echo "$1 $from $(now)" >>"$out/windows.txt"
}
sleep 0.5
window calm 1.5
window fem_slow 3 "$fem"
window calm 3
window haptic_slow 3 "$haptic"
window calm 3
wait "$gateway" || { echo "overload_test: the gateway exited with $?" >&2; exit 1; }
for p in "$haptic" "$fem" "$probe"; do kill -INT "$p" 2>/dev/null || true; done
wait "$haptic" || { echo "overload_test: the haptic service exited with $?" >&2; exit 1; }
wait "$fem" || { echo "overload_test: the FEM exited with $?" >&2; exit 1; }
wait "$probe" || true
pids=()

status=0
echo "overload_test: rates, each window against the calm ones"
python3 "$repo/tests/faults/window_rates.py" "$out/probe.txt" "$out/windows.txt" \
  fem_slow:gateway:0.99 fem_slow:haptic:0.99 haptic_slow:gateway:0.99 haptic_slow:fem:0.90 |
  tee "$out/rates.md" || status=1
fem_lost=$(grep -c "^haptic: FEM lost" "$out/haptic.log" || true)
silences=$(sed -n 's/.*silences \([0-9]*\),.*/\1/p' "$out/gateway.log" | tail -n 1)
late=$(sed -n 's/.*periods > 1.5 ms: \([0-9]*\).*/\1/p' "$out/haptic.log" | tail -n 1)
behind=$(sed -n 's/^fahr_fem_service: \([0-9]*\) times more than 10 steps behind.*/\1/p' "$out/fem.log" | tail -n 1)
echo "overload_test: the haptic service said the FEM lost ${fem_lost:-0} times; the gateway counted ${silences:-0} silences of the haptic service; the haptic service's periods > 1.5 ms ${late:-0}; the FEM ${behind:-0} times more than 10 steps behind"
check() {  # check DESCRIPTION COMMAND...
  local what=$1; shift
  if "$@"; then echo "  ok    $what"; else echo "  FAIL  $what"; status=1; fi
}
check "the slow FEM is reported (the haptic service says it lost the FEM)" [ "${fem_lost:-0}" -ge 1 ]
check "the slow haptic service is reported (the gateway counts its silences)" [ "${silences:-0}" -ge 1 ]
exit "$status"
