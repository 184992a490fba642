#!/usr/bin/env bash
# The intubation benchmark (the paper's Figure 6 setting): the whole stack
# in real time (deployment/run_local.sh: gateway with the simulated hand on
# the intubation script, FEM service, haptic service, as separate processes
# over DDS) for S seconds, once with the AIST and once with the
# triangle-level baseline finding the blade's contacts with the tongue;
# prints the haptic tick's thread-CPU time (median, p99, p99.9, max over the
# whole run) and the number of tick periods longer than 1.5 ms, each run's
# tick parts as the haptic service prints them, the FEM service's end lines
# (stale ContactSets, resets, its slowest step) and each run's summary.
#
#   bench/intubation.sh [BUILD_DIR] [--seconds 60] [--dds cyclonedds] [--scene FILE]
#                       [--cpus-fem LIST --cpus-haptic LIST] [--only aist|triangle]
#                       [--markdown [FILE]]
#
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/intubation.md, under the header every
# bench writes (fahr_bench_results, bench/support).
# The script lasts 13 s; the gateway repeats it. Numbers depend on what
# else the machine runs (three processes share its cores): compare the two
# rows of one run, not runs of different days.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
command=("$0" "$@")
build="$repo/build"
seconds=60
dds=cyclonedds
scene_flags=()
pin_flags=()
collisions=(aist triangle)
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --dds) dds="$2"; shift 2 ;;
    --scene) scene_flags=(--scene "$2"); shift 2 ;;
    --cpus-fem|--cpus-haptic) pin_flags+=("$1" "$2"); shift 2 ;;
    --only) collisions=("$2"); shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    --markdown=*) markdown=("$1"); shift ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    -*) echo "intubation: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "intubation: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 2
fi

load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
out=$(mktemp -d /tmp/fahr-intubation-bench-XXXXXX)
trap 'rm -rf "$out"' EXIT
for collision in "${collisions[@]}"; do
  echo "intubation: $collision, ${seconds} s ..." >&2
  FAHR_RUN_LOG_DIR="$out/$collision" bash "$repo/deployment/run_local.sh" "$build" --dds "$dds" \
    --duration-s "$seconds" --haptic-collision "$collision" "${scene_flags[@]}" "${pin_flags[@]}" >"$out/$collision.txt" 2>&1 ||
    { cat "$out/$collision.txt" >&2; exit 1; }
done

tables() {
  echo "## Intubation in real time: AIST and triangle baseline, ${seconds} s each ($dds)"
  echo
  echo "| collision | ticks | tick CPU median us | p99 us | p99.9 us | max us | periods > 1.5 ms | peak tissue reaction N | FEM states used |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
  for collision in "${collisions[@]}"; do
    log="$out/$collision/haptic.log"
    line=$(grep "tick CPU us median" "$log")
    read -r median p99 p999 max ticks long <<<"$(sed -E 's/.*median ([0-9]+) p99 ([0-9]+) p99.9 ([0-9]+) max ([0-9]+) over ([0-9]+) ticks; periods > 1.5 ms: ([0-9]+).*/\1 \2 \3 \4 \5 \6/' <<<"$line")"
    reaction=$(awk -F'|' '{ gsub(/^ +| +$/, "", $2) } $2 == "peak tissue reaction N" { gsub(/ /, "", $3); print $3 }' "$out/$collision.txt")
    used=$(sed -nE 's/.* ticks on ([0-9]+) FEM states.*/\1/p' "$log")
    echo "| $collision | $ticks | $median | $p99 | $p999 | $max | $long | ${reaction:-?} | ${used:-?} |"
  done
  # Where the tick's time goes (the haptic service's own breakdown).
  for collision in "${collisions[@]}"; do
    echo
    echo "$collision, tick parts:"
    echo
    sed -nE 's/^fahr_haptic_service: (tick part .*)/    \1/p' "$out/$collision/haptic.log"
  done
  # The FEM service's end lines: stale ContactSets (ignored, the tongue then
  # stepped without the tool), resets, its slowest step and what it did.
  for collision in "${collisions[@]}"; do
    echo
    echo "$collision, FEM service:"
    echo
    sed -nE "s/^fahr_fem_service: ((body '[^']*': )?([0-9]+ steps, stale .*|slowest step .*))/    \\1/p" \
      "$out/$collision/fem.log"
  done
  # Each run's summary (fahr_run_summary's tables, as run_local.sh prints them).
  for collision in "${collisions[@]}"; do
    echo
    echo "### Run summary, $collision"
    echo
    # Its table lines, a blank line between two tables.
    awk '/^\|/ { if (gap && seen) print ""; print; seen = 1; gap = 0; next } { gap = 1 }
         END { if (!seen) print "(no summary table)" }' "$out/$collision.txt"
  done
}

if [ ${#markdown[@]} -gt 0 ]; then
  tables | "$results" intubation "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}"
else
  tables
fi
