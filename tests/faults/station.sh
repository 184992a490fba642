# Sourced by hostile_test.sh and overload_test.sh: one station run in real
# time, recorded by fault_probe, and a cgroup that holds a process to a share
# of one core.
#
# The caller sets: name (for messages), repo, build, vendor, domain, out,
# run_s, and FAHR_KEEP (non-empty keeps $out).
#
#   station_start     FEM and haptic service (waits for their ready lines),
#                     fault_probe --states, then the gateway on the scripted
#                     intubation for run_s seconds; sets fem, haptic, probe,
#                     gateway (pids)
#   station_stop      waits for the gateway, stops the others, fails on a
#                     service that did not exit cleanly
#   check DESCRIPTION COMMAND...   prints ok/FAIL, sets status=1 on a failure
#   ge A B            A >= B (numbers)
#
# `ip netns exec` mounts a fresh /sys, so the cpu controller is mounted here
# (cgroup v1 "cpu", else v2 with cpu.max); a machine with neither fails.
#
#   quota_mount                 once: mounts the controller ($quota_root)
#   quota_group NAME PERCENT    makes $quota_root/NAME at PERCENT of a core
#   quota_put NAME PID          moves PID (all its threads) into it
#   quota_release PID           moves PID back to the root group
#   quota_unmount               removes the groups and the mount
scene="$repo/deployment/scenes/neonatal_intubation.yaml"
flags=(--dds "$vendor" --domain "$domain")
mkdir -p "$out"
gateway_exe="$build/services/device_gateway/fahr_device_gateway"
fem_exe="$build/services/fem/fahr_fem_service"
haptic_exe="$build/services/haptic/fahr_haptic_service"
probe_exe="$build/tests/faults/fault_probe"
for exe in "$gateway_exe" "$fem_exe" "$haptic_exe" "$probe_exe"; do
  [ -x "$exe" ] || { echo "$name: $exe is missing (build it)" >&2; exit 1; }
done
# The station at a high CFS weight, as in fault_test.sh: these tests are
# about one process's load, not about other work on a shared machine.
nice_level=${FAHR_STATION_NICE:--15}
# The gateway's and the haptic service's 1 kHz ticks SCHED_FIFO, as a lab
# station runs them (tools/lab rt_priority): without it, on a 2-core machine
# whose FEM misses its rate and so never sleeps, a flood's decoding took the
# haptic service to 0.80-0.89 of its calm rate (0.845 in one run, 1.000
# with it). FAHR_STATION_RT=0: normal scheduling.
rt_priority=${FAHR_STATION_RT:-80}
rt_flags=()
[ "$rt_priority" = 0 ] || rt_flags=(--rt-priority "$rt_priority")
status=0

pids=()
station_cleanup() {
  for pid in "${pids[@]}"; do kill -CONT "$pid" 2>/dev/null || true; kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  quota_unmount
  [ -n "${FAHR_KEEP:-}" ] || rm -rf "$out"
}
trap station_cleanup EXIT

wait_for() {  # wait_for LOG PATTERN TIMEOUT_S
  local deadline=$(( $(date +%s) + $3 ))
  until grep -q "$2" "$1" 2>/dev/null; do
    [ "$(date +%s)" -lt "$deadline" ] || { echo "$name: '$2' not in $1 within $3 s" >&2; tail -n 20 "$1" >&2; return 1; }
    sleep 0.05
  done
}

station_start() {
  echo "$name: $vendor, domain $domain, a ${run_s} s run, files in $out"
  nice -n "$nice_level" "$fem_exe" --scene "$scene" "${flags[@]}" --mode realtime --duration-s "$((run_s + 30))" >"$out/fem.log" 2>&1 &
  fem=$!; pids+=("$fem")
  nice -n "$nice_level" "$haptic_exe" --scene "$scene" "${flags[@]}" "${rt_flags[@]}" --mode realtime --duration-s "$((run_s + 30))" >"$out/haptic.log" 2>&1 &
  haptic=$!; pids+=("$haptic")
  wait_for "$out/fem.log" "Hz, realtime" 180
  wait_for "$out/haptic.log" "fahr_haptic_service: ready" 180
  nice -n "$nice_level" "$probe_exe" "${flags[@]}" --states --duration-s "$((run_s + 30))" --out "$out/probe.txt" >"$out/probe.log" 2>&1 &
  probe=$!; pids+=("$probe")
  sleep 1  # the probe's readers match before the first DevicePose
  nice -n "$nice_level" "$gateway_exe" "${flags[@]}" "${rt_flags[@]}" --backend simulated --script intubation --duration-s "$run_s" \
    >"$out/gateway.log" 2>&1 &
  gateway=$!; pids+=("$gateway")
}

station_stop() {
  wait "$gateway" || { echo "$name: the gateway exited with $?" >&2; exit 1; }
  for p in "$haptic" "$fem" "$probe"; do kill -INT "$p" 2>/dev/null || true; done
  wait "$haptic" || { echo "$name: the haptic service exited with $?" >&2; exit 1; }
  wait "$fem" || { echo "$name: the FEM exited with $?" >&2; exit 1; }
  wait "$probe" || true
  pids=()
}

check() {  # check DESCRIPTION COMMAND...
  local what=$1; shift
  if "$@"; then echo "  ok    $what"; else echo "  FAIL  $what"; status=1; fi
}
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a >= b) }'; }

quota_root=""
quota_v=""
quota_mount() {
  quota_root=$(mktemp -d /tmp/fahr-quota-XXXXXX)
  if mount -t cgroup -o cpu cgroup "$quota_root" 2>/dev/null; then
    quota_v=1
  elif mount -t cgroup2 none "$quota_root" 2>/dev/null && grep -qw cpu "$quota_root/cgroup.controllers"; then
    quota_v=2
    echo +cpu >"$quota_root/cgroup.subtree_control" 2>/dev/null || true
  else
    rmdir "$quota_root"; quota_root=""
    echo "cpu_quota: cannot mount a cgroup cpu controller (v1 cpu or v2 cpu.max)" >&2
    return 1
  fi
}
quota_group() {
  local dir="$quota_root/$1" quota_us=$(( $2 * 1000 ))
  mkdir -p "$dir"
  if [ "$quota_v" = 1 ]; then
    echo 100000 >"$dir/cpu.cfs_period_us"
    echo "$quota_us" >"$dir/cpu.cfs_quota_us"
  else
    echo "$quota_us 100000" >"$dir/cpu.max"
  fi
}
quota_put() { echo "$2" >"$quota_root/$1/cgroup.procs"; }
quota_release() { echo "$1" >"$quota_root/cgroup.procs" 2>/dev/null || true; }
quota_unmount() {
  [ -n "$quota_root" ] || return 0
  for dir in "$quota_root"/*/; do
    [ -e "$dir/cgroup.procs" ] || continue
    while read -r pid; do quota_release "$pid"; done <"$dir/cgroup.procs"
    rmdir "$dir" 2>/dev/null || true
  done
  umount "$quota_root" 2>/dev/null || true
  rmdir "$quota_root" 2>/dev/null || true
}
