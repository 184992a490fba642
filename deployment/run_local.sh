#!/usr/bin/env bash
# The end-to-end run on one machine: the device gateway (simulated
# hand on the scripted intubation), the FEM service and the haptic service as
# separate processes on one DDS vendor and domain, with fahr_run_summary
# listening for the run's duration; then stops them and prints the summary.
#
#   deployment/run_local.sh [BUILD_DIR] [--dds cyclonedds|fastdds] [--domain N]
#                           [--duration-s S] [--scene FILE] [--script intubation|overshoot]
#                           [--dds-gateway V] [--dds-fem V] [--dds-haptic V]
#                           [--mode realtime|lockstep] [--haptic-collision aist|triangle]
#                           [--cpus-fem LIST] [--cpus-haptic LIST]
#                           [--record FILE.mcap] [--record-decimate TOPIC=N] [--record-arg ARG]
#                           [--replay FILE.mcap] [--security DIR] [--pace R]
#                           [--summary-arg ARG] [--rt-priority N]
#
# --record FILE.mcap: fahr_logger joins first and records every topic of the
# run to FILE.mcap (FILE.mcap.part until it closes, after the services have
# stopped and sent their last reports); its per-writer table of sent,
# recorded, lost and dropped samples is printed at the end.
# --record-decimate fahr/DeformationState=10 keeps one FEM state in ten
# (the others are counted as skipped): the recording's size bound.
# --record-arg ARG passes one more argument to fahr_logger (repeatable).
# --replay FILE.mcap (lockstep only): fahr_replay stands in for the gateway
# and feeds the recorded run's DevicePoses, step by step; the haptic and FEM
# hashes then equal the recorded run's.
# --security DIR: DDS Security on every participant, with the station's
# files in DIR (deployment/security/make_station_security.sh); each program
# joins with its own identity.
# --haptic-collision triangle: the haptic service finds the blade's contacts
# with the tongue by the triangle-level baseline instead of the AIST.
# --cpus-fem / --cpus-haptic: run that service on these CPUs only (its
# --cpus, libs/runtime cpu_pinning.h), e.g. --cpus-fem 1 --cpus-haptic 0
# keeps the FEM's steps off the core the haptic tick runs on.
# --mode lockstep: the services advance together in simulated time under
# fahr_lockstep_clock (duration-s of simulated time, as fast as the machine
# allows); the clock prints each service's output hash, the same on every
# run and every vendor mix. No run summary then (wall-clock rates mean
# nothing in lockstep); each service prints its own figures at the end.
# --pace R (lockstep only): the clock lets simulated time run at most R
# times as fast as wall time (1: real time at most, for a viewer); the
# hashes stay the same.
# --summary-arg ARG passes one more argument to fahr_run_summary (realtime;
# repeatable), e.g. --summary-arg --tick-spans --summary-arg FILE.csv.
# --rt-priority N (realtime): the gateway's servo loop and the haptic tick
# run under SCHED_FIFO at priority N, default 70 (0: the default scheduler),
# so the FEM's steps and factorisations beside them on a machine with few
# cores never delay a 1 kHz tick; a service the kernel refuses it to says
# so and runs on without it. Neither loop spins unless asked (--spin).
#
# --dds-<service> puts one service on another vendor (a mixed-vendor run);
# the summary listens with --dds.
# BUILD_DIR defaults to $FAHR_BUILD_DIR, else build/. As root the whole run
# happens inside tests/run_in_netns.sh (a loopback-only network namespace);
# otherwise every participant gets the loopback profile of deployment/dds.
# Logs of each process go to $FAHR_RUN_LOG_DIR (default: a fresh temporary
# folder, printed at the end). Exit status: 0 if every service ran and the
# summary printed, non-zero otherwise.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)

build="${FAHR_BUILD_DIR:-$repo/build}"
dds=cyclonedds
domain=42
duration_s=20
scene="$repo/deployment/scenes/neonatal_intubation.yaml"
script=intubation
dds_gateway=""
dds_fem=""
dds_haptic=""
mode=realtime
haptic_collision=aist
fem_extra=()
haptic_extra=()
record=""
record_extra=()
replay=""
security=""
clock_extra=()
summary_extra=()
rt_priority=70
args=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) dds="$2"; shift 2 ;;
    --domain) domain="$2"; shift 2 ;;
    --duration-s) duration_s="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --script) script="$2"; shift 2 ;;
    --dds-gateway) dds_gateway="$2"; shift 2 ;;
    --dds-fem) dds_fem="$2"; shift 2 ;;
    --dds-haptic) dds_haptic="$2"; shift 2 ;;
    --mode) mode="$2"; shift 2 ;;
    --haptic-collision) haptic_collision="$2"; shift 2 ;;
    --cpus-fem) fem_extra+=(--cpus "$2"); shift 2 ;;
    --cpus-haptic) haptic_extra+=(--cpus "$2"); shift 2 ;;
    --record) record="$2"; shift 2 ;;
    --record-decimate) record_extra+=(--decimate "$2"); shift 2 ;;
    --record-arg) record_extra+=("$2"); shift 2 ;;
    --replay) replay="$2"; shift 2 ;;
    --security) security=$(cd "$2" && pwd); shift 2 ;;
    --pace) clock_extra+=(--pace "$2"); shift 2 ;;
    --summary-arg) summary_extra+=("$2"); shift 2 ;;
    --rt-priority) rt_priority="$2"; shift 2 ;;
    -h|--help) sed -n '2,57p' "$0"; exit 0 ;;
    -*) echo "run_local: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
dds_gateway="${dds_gateway:-$dds}"
dds_fem="${dds_fem:-$dds}"
dds_haptic="${dds_haptic:-$dds}"
case "$mode" in realtime|lockstep) ;; *) echo "run_local: --mode must be realtime or lockstep, not '$mode'" >&2; exit 2 ;; esac
case "$rt_priority" in ''|*[!0-9]*) echo "run_local: --rt-priority must be 0-99, not '$rt_priority'" >&2; exit 2 ;; esac
[ "$rt_priority" -le 99 ] || { echo "run_local: --rt-priority must be 0-99, not '$rt_priority'" >&2; exit 2; }
rt_flags=()
[ "$mode" = realtime ] && [ "$rt_priority" -gt 0 ] && rt_flags=(--rt-priority "$rt_priority")
for v in "$dds" "$dds_gateway" "$dds_fem" "$dds_haptic"; do
  case "$v" in cyclonedds|fastdds) ;; *) echo "run_local: a DDS vendor must be cyclonedds or fastdds, not '$v'" >&2; exit 2 ;; esac
done

# As root: re-enter inside a loopback-only namespace, so the run never
# touches a real network (and concurrent runs on the host cannot meet it).
if [ "$(id -u)" -eq 0 ] && [ -z "${FAHR_RUN_LOCAL_IN_NETNS:-}" ]; then
  FAHR_RUN_LOCAL_IN_NETNS=1 exec "$repo/tests/run_in_netns.sh" bash "$0" "${args[@]}"
fi

gateway="$build/services/device_gateway/fahr_device_gateway"
fem="$build/services/fem/fahr_fem_service"
haptic="$build/services/haptic/fahr_haptic_service"
summary="$build/tools/run_summary/fahr_run_summary"
clock="$build/services/lockstep_clock/fahr_lockstep_clock"
logger="$build/services/logger/fahr_logger"
needed=("$gateway" "$fem" "$haptic" "$summary")
[ "$mode" = lockstep ] && needed+=("$clock")
[ -n "$record" ] && needed+=("$logger")
replayer="$build/tools/replay/fahr_replay"
if [ ${#clock_extra[@]} -gt 0 ] && [ "$mode" != lockstep ]; then
  echo "run_local: --pace needs --mode lockstep" >&2; exit 2
fi
if [ -n "$replay" ]; then
  [ "$mode" = lockstep ] || { echo "run_local: --replay needs --mode lockstep" >&2; exit 2; }
  needed+=("$replayer")
fi
for exe in "${needed[@]}"; do
  if [ ! -x "$exe" ]; then
    echo "run_local: $exe is missing; build it: cmake --build $build --target fahr_device_gateway fahr_fem_service fahr_haptic_service fahr_run_summary fahr_lockstep_clock fahr_logger" >&2
    exit 2
  fi
done

# The transport flags of a participant on vendor $1: outside a namespace,
# with the vendor's loopback profile.
transport_flags() {
  local vendor=$1
  printf '%s\n' --dds "$vendor" --domain "$domain"
  if [ -n "$security" ]; then printf '%s\n' --security "$security"; fi
  if [ -z "${FAHR_RUN_LOCAL_IN_NETNS:-}" ]; then
    printf '%s\n' --dds-profile "$repo/deployment/dds/${vendor}_loopback.xml"
  fi
}
mapfile -t common < <(transport_flags "$dds")
mapfile -t gateway_flags < <(transport_flags "$dds_gateway")
mapfile -t fem_flags < <(transport_flags "$dds_fem")
mapfile -t haptic_flags < <(transport_flags "$dds_haptic")

logs="${FAHR_RUN_LOG_DIR:-$(mktemp -d /tmp/fahr-run-XXXXXX)}"
mkdir -p "$logs"
pids=()

# Stops one process: SIGINT, then SIGTERM, then SIGKILL, a few seconds apart.
stop() {
  local pid=$1
  kill -0 "$pid" 2>/dev/null || return 0
  for signal in INT TERM; do
    kill -s "$signal" "$pid" 2>/dev/null || true
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || return 0
      sleep 0.1
    done
  done
  echo "run_local: process $pid ignored SIGINT and SIGTERM; killing it" >&2
  kill -s KILL "$pid" 2>/dev/null || true
}
cleanup() {
  for pid in "${pids[@]}"; do stop "$pid"; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Waits until a log shows a line, or the process died, or time ran out.
wait_for_line() {  # wait_for_line LOG PATTERN PID SECONDS (of wall time, however late sleeps wake)
  local log=$1 pattern=$2 pid=$3 timeout_s=$4
  local until=$((SECONDS + timeout_s))
  while [ "$SECONDS" -lt "$until" ]; do
    grep -q "$pattern" "$log" 2>/dev/null && return 0
    kill -0 "$pid" 2>/dev/null || { echo "run_local: $(basename "$log" .log) exited during set-up:" >&2; tail -n 20 "$log" >&2; return 1; }
    sleep 0.1
  done
  echo "run_local: $(basename "$log" .log) not ready after ${timeout_s} s" >&2
  return 1
}

echo "run_local: gateway $dds_gateway, fem $dds_fem, haptic $dds_haptic, domain $domain, ${duration_s} s of the '$script' script, $mode, logs in $logs"
# The recorder joins first, so it matches every writer before its first sample.
logger_pid=""
if [ -n "$record" ]; then
  mkdir -p "$(dirname "$record")"
  [ "$mode" = lockstep ] && record_extra+=(--lockstep)
  "$logger" -o "$record" "${common[@]}" --scene "$scene" "${record_extra[@]}" >"$logs/logger.log" 2>&1 &
  logger_pid=$!; pids+=("$logger_pid")
  wait_for_line "$logs/logger.log" "recording to" "$logger_pid" 30
fi
# Stops the recorder after the services, so their last reports are in the
# file, and prints its table and the file's name.
finish_recording() {
  [ -n "$logger_pid" ] || return 0
  sleep 0.5
  stop "$logger_pid"
  wait "$logger_pid" 2>/dev/null || { echo "run_local: the logger failed:" >&2; tail -n 20 "$logs/logger.log" >&2; return 1; }
  echo "run_local: recording (per writer: sent = recorded + gaps + drops + skipped; (before): gaps before the recorder matched the writer):"
  grep "^fahr_logger: " "$logs/logger.log" | grep -v "recording to\|writers matched" | sed 's/^fahr_logger: /  /'
}
stdbuf -oL "$fem" --scene "$scene" "${fem_flags[@]}" "${fem_extra[@]}" --mode "$mode" --duration-s 0 >"$logs/fem.log" 2>&1 &
fem_pid=$!; pids+=("$fem_pid")
"$haptic" --scene "$scene" "${haptic_flags[@]}" "${haptic_extra[@]}" "${rt_flags[@]}" --mode "$mode" --collision "$haptic_collision" --duration-s 0 \
  >"$logs/haptic.log" 2>&1 &
haptic_pid=$!; pids+=("$haptic_pid")
# (stdbuf: the services print their start line with printf; line buffering
# gets it into the log while they run.)
# The gateway's script starts with its first tick: start it only when both
# services have built their meshes, spheres and fields.
# 180 s: the haptic service's set-up alone took 48-53 s on a slow 2-core VM.
wait_for_line "$logs/fem.log" "^fahr_fem_service: " "$fem_pid" 180
wait_for_line "$logs/haptic.log" "ready" "$haptic_pid" 180

if [ "$mode" = lockstep ]; then
  if [ -n "$replay" ]; then
    "$replayer" "$replay" --mode lockstep "${gateway_flags[@]}" >"$logs/gateway.log" 2>&1 &
  else
    # The gateway runs the clock's steps: past the script's end (13 s of the
    # intubation) the hand holds its last pose, as in real time.
    stdbuf -oL "$gateway" "${gateway_flags[@]}" --mode lockstep --force-input-period 1 --backend simulated \
      --script "$script" --duration-s "$duration_s" >"$logs/gateway.log" 2>&1 &
  fi
  gateway_pid=$!; pids+=("$gateway_pid")
  if [ -n "$logger_pid" ]; then
    # The recorder must have every stream's writer before step 0: a lockstep
    # writer keeps its last 8 steps for a reader that matches late, and a
    # starved machine's discovery took seconds (a recording that began
    # 3.9 s into the script). The writers exist before the clock's grant.
    matched="writers matched: fahr/DevicePose [1-9][0-9]*, fahr/ForceCommand [1-9][0-9]*, fahr/ContactSet [1-9][0-9]*, fahr/DeformationState [1-9]"
    wait_for_line "$logs/logger.log" "$matched" "$logger_pid" 120 ||
      echo "run_local: the recorder has not matched every writer; the recording may lack the first steps" >&2
  fi
  steps=$(awk "BEGIN { printf \"%d\", $duration_s * 1000 }")
  status=0
  "$clock" --participants device_gateway,fem,haptic --steps "$steps" "${common[@]}" "${clock_extra[@]}" \
    | tee "$logs/clock.log" || status=$?
  for name in gateway haptic fem; do
    pid_var="${name}_pid"
    # The clock told them to stop; give them a moment to print their figures.
    for _ in $(seq 50); do kill -0 "${!pid_var}" 2>/dev/null || break; sleep 0.1; done
    stop "${!pid_var}"
    wait "${!pid_var}" 2>/dev/null || true
  done
  finish_recording || status=1
  pids=()
  echo "run_local: service logs:"
  for name in gateway fem haptic; do tail -n 3 "$logs/$name.log" | sed "s/^/  [$name] /"; done
  echo "run_local: logs in $logs"
  exit "$status"
fi

# The summary listens a little longer than the gateway runs, so it sees the
# services' last reports.
"$summary" --duration-s "$(awk "BEGIN { print $duration_s + 2 }")" "${common[@]}" "${summary_extra[@]}" \
  >"$logs/summary.md" 2>"$logs/summary.err" &
summary_pid=$!; pids+=("$summary_pid")
sleep 0.5  # the summary's readers match before the first DevicePose
stdbuf -oL "$gateway" "${gateway_flags[@]}" "${rt_flags[@]}" --backend simulated --script "$script" \
  --duration-s "$duration_s" >"$logs/gateway.log" 2>&1 &
gateway_pid=$!; pids+=("$gateway_pid")

status=0
wait "$gateway_pid" || { status=$?; echo "run_local: the gateway exited with $status" >&2; tail -n 20 "$logs/gateway.log" >&2; }
wait "$summary_pid" || { status=$?; echo "run_local: the summary exited with $status" >&2; cat "$logs/summary.err" >&2; }
for name in haptic fem; do
  pid_var="${name}_pid"
  pid=${!pid_var}
  if ! kill -0 "$pid" 2>/dev/null; then
    echo "run_local: $name died during the run:" >&2
    tail -n 20 "$logs/$name.log" >&2
    status=1
  fi
  stop "$pid"
  wait "$pid" 2>/dev/null || true
done
finish_recording || status=1
pids=()

cat "$logs/summary.md"
echo
echo "run_local: service logs:"
for name in gateway fem haptic; do tail -n 3 "$logs/$name.log" | sed "s/^/  [$name] /"; done
echo "run_local: logs in $logs"
exit "$status"
