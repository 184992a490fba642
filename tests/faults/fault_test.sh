#!/usr/bin/env bash
# Each service killed (SIGKILL, then restarted) and stopped (SIGSTOP, then
# SIGCONT) mid-intubation, in real time, as separate processes: the FEM and
# haptic services and the logger run for the whole test; each case starts a
# fresh gateway on the scripted intubation, injects its fault at 7 s of the
# script (the blade levering the tongue), restarts or continues the service,
# and ends once the service is back (at least at 12 s of the script).
# fault_probe listens to every DevicePose and ForceCommand of the case;
# analyse.py prints the table (service x signal: detected after, force on
# the device, zero after, recovered after, run completed) and judges it.
#
#   fault_test.sh BUILD_DIR VENDOR [SERVICE:SIGNAL ...]
#
# SERVICE: fem, haptic, gateway, logger; SIGNAL: KILL or STOP; none:NONE is
# the control, the same script with no fault (what the station does in that
# window anyway). Default: the control and all eight. Runs inside a
# loopback-only network namespace (tests/run_in_netns.sh)
# or with FAHR_FAULTS_NO_NETNS=1 on a machine where that is fine.
# FAHR_KEEP_FAULTS=DIR keeps logs, probe files and the table there.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: fault_test.sh BUILD_DIR VENDOR [SERVICE:SIGNAL ...]}" && pwd)
vendor=${2:?usage: fault_test.sh BUILD_DIR VENDOR [SERVICE:SIGNAL ...]}
shift 2
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(none:NONE fem:KILL fem:STOP haptic:KILL haptic:STOP gateway:KILL
  gateway:STOP logger:KILL logger:STOP)

domain=${FAHR_FAULTS_DOMAIN:-61}
scene="$repo/deployment/scenes/neonatal_intubation.yaml"
flags=(--dds "$vendor" --domain "$domain")
out=${FAHR_KEEP_FAULTS:-$(mktemp -d /tmp/fahr-faults-XXXXXX)}
mkdir -p "$out"
gateway_exe="$build/services/device_gateway/fahr_device_gateway"
fem_exe="$build/services/fem/fahr_fem_service"
haptic_exe="$build/services/haptic/fahr_haptic_service"
logger_exe="$build/services/logger/fahr_logger"
probe_exe="$build/tests/faults/fault_probe"
for exe in "$gateway_exe" "$fem_exe" "$haptic_exe" "$logger_exe" "$probe_exe"; do
  [ -x "$exe" ] || { echo "fault_test: $exe is missing (build it)" >&2; exit 1; }
done

# When the fault strikes, in seconds of the gateway's script, and the
# shortest case.
fault_at_s=7.0
case_min_s=12.0
restart_after_s=0.3
stop_for_s=1.0
# Time left after a restarted service's ready line for it to be back in the
# loop: discovery of its new participant, a first FEM step, the slew. 2 s
# on a machine that keeps real time; a starved one's discovery alone can
# take seconds.
after_back_s=5

# The station's processes run at a high CFS weight (nice -15): on a shared
# machine other work would otherwise starve the FEM's steps past the 50 ms
# loss timeout. FAHR_FAULTS_NICE=0 runs them at normal weight.
nice_level=${FAHR_FAULTS_NICE:--15}

pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -CONT "$pid" 2>/dev/null || true; kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [ -n "${FAHR_KEEP_FAULTS:-}" ] || rm -rf "$out"
}
trap cleanup EXIT

now_ns() { date +%s%N; }
# Occurrences of a pattern in a log (services are restarted into the same log).
count_of() { grep -c "$2" "$1" 2>/dev/null || true; }
wait_count() {  # wait_count LOG PATTERN COUNT TIMEOUT_S
  local deadline=$(( $(date +%s) + $4 ))
  while [ "$(count_of "$1" "$2")" -lt "$3" ]; do
    [ "$(date +%s)" -lt "$deadline" ] || { echo "fault_test: '$2' not seen in $1 within $4 s" >&2; tail -n 20 "$1" >&2; return 1; }
    sleep 0.05
  done
}

start_fem() {
  nice -n "$nice_level" "$fem_exe" --scene "$scene" "${flags[@]}" --mode realtime --duration-s 0 >>"$out/fem.log" 2>&1 &
  fem_pid=$!; pids+=("$fem_pid")
}
start_haptic() {
  nice -n "$nice_level" "$haptic_exe" --scene "$scene" "${flags[@]}" --mode realtime --duration-s 0 >>"$out/haptic.log" 2>&1 &
  haptic_pid=$!; pids+=("$haptic_pid")
}
logger_runs=0
start_logger() {
  logger_runs=$((logger_runs + 1))
  nice -n "$nice_level" "$logger_exe" -o "$out/run-$logger_runs.mcap" "${flags[@]}" --scene "$scene" >>"$out/logger.log" 2>&1 &
  logger_pid=$!; pids+=("$logger_pid")
}
start_gateway() {
  nice -n "$nice_level" "$gateway_exe" "${flags[@]}" --backend simulated --script intubation --duration-s 600 \
    >>"$out/gateway.log" 2>&1 &
  gateway_pid=$!; pids+=("$gateway_pid")
}
# The ready lines, counted: each start adds one.
fem_ready="Hz, realtime"
haptic_ready="fahr_haptic_service: ready"
logger_ready="recording to"
gateway_ready="fahr_device_gateway: $vendor"

echo "fault_test: $vendor, domain $domain, cases ${cases[*]}, files in $out"
start_logger
wait_count "$out/logger.log" "$logger_ready" 1 60
start_fem
start_haptic
wait_count "$out/fem.log" "$fem_ready" 1 180
wait_count "$out/haptic.log" "$haptic_ready" 1 180
echo "fault_test: services ready"

: >"$out/cases.txt"
n=0
for c in "${cases[@]}"; do
  n=$((n + 1))
  service=${c%%:*}
  signal=${c##*:}
  case "$service:$signal" in
    fem:KILL|fem:STOP|haptic:KILL|haptic:STOP|gateway:KILL|gateway:STOP|logger:KILL|logger:STOP|none:NONE) ;;
    *) echo "fault_test: unknown case '$c' (SERVICE:KILL|STOP, or none:NONE)" >&2; exit 2 ;;
  esac
  nice -n "$nice_level" "$probe_exe" "${flags[@]}" --duration-s 600 --out "$out/probe-$n.txt" >"$out/probe-$n.log" 2>&1 &
  probe_pid=$!; pids+=("$probe_pid")
  sleep 1  # the probe's readers match before the first DevicePose
  gateways_before=$(count_of "$out/gateway.log" "$gateway_ready")
  start_gateway
  wait_count "$out/gateway.log" "$gateway_ready" $((gateways_before + 1)) 30
  start_ns=$(now_ns)
  sleep "$fault_at_s"
  fault_ns=$(now_ns)
  back_ns=$fault_ns  # the control (NONE): the same script, no fault
  if [ "$signal" != NONE ]; then
    pid_var="${service}_pid"
    victim=${!pid_var}
    kill -s "$signal" "$victim"
  fi
  if [ "$signal" = KILL ]; then
    wait "$victim" 2>/dev/null || true
    sleep "$restart_after_s"
    ready_var="${service}_ready"
    log="$out/$service.log"
    before=$(count_of "$log" "${!ready_var}")
    back_ns=$(now_ns)
    "start_$service"
    # The restarted service must be back within the test's bound.
    wait_count "$log" "${!ready_var}" $((before + 1)) 180
  elif [ "$signal" = STOP ]; then
    sleep "$stop_for_s"
    back_ns=$(now_ns)
    kill -CONT "$victim"
  fi
  # At least case_min_s of script, and after_back_s after the service is back.
  ready_ns=$(now_ns)
  end_ns=$(( start_ns + $(awk "BEGIN { printf \"%d\", $case_min_s * 1e9 }") ))
  after_ns=$((ready_ns + after_back_s * 1000000000))
  [ "$after_ns" -gt "$end_ns" ] && end_ns=$after_ns
  while [ "$(now_ns)" -lt "$end_ns" ]; do sleep 0.05; done
  completed=1
  for s in fem haptic logger gateway; do
    v="${s}_pid"
    kill -0 "${!v}" 2>/dev/null || { echo "fault_test: case $c: $s is not running at the end" >&2; completed=0; }
  done
  kill -INT "$gateway_pid"
  wait "$gateway_pid" || { echo "fault_test: case $c: the gateway exited with $?" >&2; completed=0; }
  kill -INT "$probe_pid"
  wait "$probe_pid" || true
  echo "$n $service $signal $start_ns $fault_ns $back_ns $ready_ns $(now_ns) $completed" >>"$out/cases.txt"
  echo "fault_test: case $n ($service $signal) done"
  sleep 2  # the tongue relaxes and the haptic service sees the gateway gone before the next case
done

status=0
python3 "$repo/tests/faults/analyse.py" "$out" | tee "$out/table.md" || status=$?
for s in fem haptic logger; do
  v="${s}_pid"
  kill -INT "${!v}" 2>/dev/null || true
done
wait 2>/dev/null || true
pids=()
echo "fault_test: service events (the haptic service's and the FEM's, as said on stderr):"
grep -h "^haptic: \|^fem: ContactSet refused: it answers" "$out/haptic.log" "$out/fem.log" | sort | uniq -c | sed 's/^/  /' || true
exit "$status"
