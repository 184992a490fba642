#!/usr/bin/env bash
# The single-host demo on mixed vendors (deployment/run_local.sh, 20 s of the
# intubation script): gateway and FEM on Fast DDS with the haptic service on
# Cyclone, and the reverse, each twice; then each vendor alone once. Per run:
# the services' rates, the FEM's steps and stale ContactSets, the haptic
# service's DevicePoses received and lost in transport (sequence gaps), FEM
# states used, and motion-to-force p99.
#
#   bench/lab/mixed_vendor.sh [BUILD_DIR] [--seconds 20] [--nice N] [--markdown [FILE]]
#
# --nice N (root): run the services at nice -N, ahead of whatever else the
# machine builds (default 15; 0 to not); the runs say so in their header.
# --markdown: also write the output under the bench header (machine,
# command, commit, date) to FILE, by default
# bench/results/<machine>/lab-mixed-vendor.md.
set -euo pipefail
load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
seconds=20
nice_level=15
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --nice) nice_level="$2"; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    -*) echo "mixed_vendor: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
results="$build/bench/support/fahr_bench_results"
prefix=()
[ "$nice_level" != 0 ] && prefix=(nice -n "-$nice_level")
out=$(mktemp /tmp/fahr-mixed-XXXXXX.md)
trap 'rm -f "$out"' EXIT
status=0
run() {
  local label=$1; shift
  local logs
  logs=$(mktemp -d /tmp/fahr-mixed-run-XXXXXX)
  {
    echo "### $label"
    echo
    echo "\`deployment/run_local.sh build $* --duration-s $seconds\` (nice -$nice_level), load average at start $(cut -d' ' -f1-3 /proc/loadavg)"
    echo
  } >>"$out"
  if FAHR_RUN_LOG_DIR="$logs" "${prefix[@]}" bash "$repo/deployment/run_local.sh" "$build" "$@" \
      --duration-s "$seconds" >"$logs/run.out" 2>&1; then
    grep -E '^\| (service|---|device_gateway|fem|haptic) ' "$logs/summary.md" >>"$out" || true
    echo >>"$out"
    grep -E 'motion_to_force_p99_ms|DevicePose samples' "$logs/summary.md" | sed 's/^/- summary: /' >>"$out" || true
    grep -h 'steps, stale contact sets' "$logs/fem.log" | sed 's/^fahr_fem_service: /- FEM: /' >>"$out" || true
    grep -h -E 'DevicePoses received|ticks on' "$logs/haptic.log" | sed 's/^fahr_haptic_service: /- haptic: /' >>"$out" || true
  else
    status=1
    echo "run failed:" >>"$out"
    tail -n 20 "$logs/run.out" | sed 's/^/    /' >>"$out"
  fi
  echo >>"$out"
  rm -rf "$logs"
}
for i in 1 2; do
  run "gateway and FEM on Fast DDS, haptic on Cyclone (run $i)" \
    --dds cyclonedds --dds-gateway fastdds --dds-fem fastdds --dds-haptic cyclonedds
  run "gateway and FEM on Cyclone, haptic on Fast DDS (run $i)" \
    --dds cyclonedds --dds-gateway cyclonedds --dds-fem cyclonedds --dds-haptic fastdds
done
run "all on Cyclone" --dds cyclonedds
run "all on Fast DDS" --dds fastdds
cat "$out"
if [ ${#markdown[@]} -gt 0 ]; then
  "$results" lab-mixed-vendor "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}" <"$out"
fi
exit "$status"
