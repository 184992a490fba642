#!/usr/bin/env bash
# The FEM's stability in real time on a starved machine: the 20 s demo
# (deployment/run_local.sh: gateway with the simulated hand on the
# intubation script, FEM and haptic services over DDS) with K busy loops at
# the same priority beside it, N times. Starved, the services fall behind
# one another: ContactSets arrive late, the haptic side loses the tongue
# for 50 ms and releases it, and the FEM steps a tongue pressed, released
# and pressed again far faster than in lockstep. Per run: the FEM's
# divergence resets (the tongue put back to rest), its steps and median
# rate, stale ContactSets, the FEM-lost episodes the haptic service saw,
# the largest inverted-tet count, and the haptic service's median rate.
#
#   bench/fem/realtime_under_load.sh [BUILD_DIR] [--runs 3] [--hogs 3] [--seconds 20]
#       [--dds cyclonedds] [--markdown [FILE]]
#
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/fem-realtime-under-load.md, under the
# header every bench writes (fahr_bench_results, bench/support). About
# (S + 20) s a run. The load is the point: run nothing else beside it.
set -euo pipefail
load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
runs=3
hogs=3
seconds=20
dds=cyclonedds
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --hogs) hogs="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --dds) dds="$2"; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    -*) echo "realtime_under_load: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
for n in "$runs" "$hogs" "$seconds"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "realtime_under_load: '$n' is not a whole number" >&2; exit 2; }
done
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "realtime_under_load: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 2
fi
work=$(mktemp -d /tmp/fahr-fem-under-load-XXXXXX)
hog_pids=()
stop_hogs() {
  [ ${#hog_pids[@]} -eq 0 ] && return 0
  kill "${hog_pids[@]}" 2>/dev/null || true
  wait "${hog_pids[@]}" 2>/dev/null || true
  hog_pids=()
}
trap 'stop_hogs; rm -rf "$work"' EXIT

# A figure from the FEM's end line: "... resets after divergence 3".
after() { grep -o "$1 [0-9]*" "$2" | tail -1 | awk '{print $NF}'; }
# The median Hz column of a service's row in the run summary.
median_hz() { awk -F'|' -v s="$1" '$2 ~ "^ *"s" *$" {gsub(/ /, "", $5); print $5}' "$2"; }

{
  echo "$runs runs of ${seconds} s ($dds), $hogs busy loops beside each, on $(nproc) cores"
  echo
  echo "| run | FEM resets | FEM steps | steps the line search shortened | FEM median Hz | stale ContactSets | FEM lost (haptic) | most inverted tets | haptic median Hz |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
} >"$work/out.md"
total_resets=0
for run in $(seq 1 "$runs"); do
  for _ in $(seq 1 "$hogs"); do
    sh -c 'while :; do :; done' &
    hog_pids+=($!)
  done
  out="$work/run$run.txt"
  "$repo/deployment/run_local.sh" "$build" --dds "$dds" --duration-s "$seconds" >"$out" 2>&1 || true
  stop_hogs
  logs=$(grep -o "logs in /tmp/fahr-run-[A-Za-z0-9]*" "$out" | head -1 | awk '{print $3}')
  fem_log="$logs/fem.log"
  if [ ! -f "$fem_log" ]; then
    echo "realtime_under_load: run $run left no FEM log; its output:" >&2
    cat "$out" >&2
    exit 1
  fi
  resets=$(after "resets after divergence" "$fem_log")
  steps=$(grep -o "fahr_fem_service: [0-9]* steps" "$fem_log" | awk '{print $2}')
  stale=$(after "stale contact sets" "$fem_log")
  inverted=$(after "max inverted elements" "$fem_log")
  shortened=$(after "line search" "$fem_log" || true)  # "-" for a FEM from before the search
  lost=$(grep -c "FEM lost:" "$out" || true)
  echo "| $run | $resets | $steps | ${shortened:--} | $(median_hz fem "$out") | $stale | $lost | $inverted | $(median_hz haptic "$out") |" >>"$work/out.md"
  total_resets=$((total_resets + resets))
  rm -rf "$logs"
done
echo >>"$work/out.md"
echo "FEM resets in all runs: $total_resets" >>"$work/out.md"
cat "$work/out.md"
if [ ${#markdown[@]} -gt 0 ]; then
  "$results" fem-realtime-under-load "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}" <"$work/out.md"
fi
