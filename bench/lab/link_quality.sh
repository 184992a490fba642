#!/usr/bin/env bash
# Which host splits a lab can use at what link quality. The station runs
# across three namespaces (tests/lab/three_hosts.sh) with fahr_udp_relay as
# the network: first with no impairment, then between the haptic host (h1,
# gateway + haptic) and the FEM host (h2) at 0.5, 2 and 5 ms one-way delay
# with 1 ms uniform jitter and at 1 % and 5 % loss; then with the gateway on
# its own host (h3, with the recorder) at 0 and 0.5 ms, and 2 ms with 1 ms
# jitter, from the haptic host. Per run what the trainee feels:
#   - motion to force: the gateway's own figure over the whole run (pose read
#     to the first servo tick shaped by the command answering it), p99;
#   - the largest force step per servo tick (the recorded DevicePoses'
#     rendered force), and the ticks above 0.1 N;
#   - the FEM state behind each ForceCommand: its age at use (> 3 FEM
#     periods: the share of ticks), and how many newer states the FEM had
#     written by then (> 3: the share of ticks; this counts the periods the
#     FEM did step, so an FEM that stalls on its own is not blamed on the
#     link); FEM states written and used; stale ContactSets;
#   - deadline misses, the passivity controller's energy (removed by it, mJ);
# and whether the split is usable there: motion-to-force p99 <= 3 ms, force
# step <= 0.1 N (p99.9 of the ticks: a contact's onset and an FEM reset
# are steps of their own, on any link), < 1 % of ticks on a state more than
# 3 FEM periods behind.
#
#   bench/lab/link_quality.sh [BUILD_DIR] [--seconds 30] [--vendors "cyclonedds fastdds"]
#       [--nice 15] [--cases "1 4"] [--markdown [FILE]]
#
# --cases: only these runs (numbered as listed above, from 1).
# --markdown: also write the output under the bench header (machine,
# command, commit, date) to FILE, by default
# bench/results/<machine>/lab-link-quality.md. Needs root. About S + 25 s a
# run, nine runs a vendor.
set -euo pipefail
load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
seconds=30
vendors="cyclonedds fastdds"
nice_level=15
only=""
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --vendors) vendors="$2"; shift 2 ;;
    --nice) nice_level="$2"; shift 2 ;;
    --cases) only=" $2 "; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -h|--help) sed -n '2,28p' "$0"; exit 0 ;;
    -*) echo "link_quality: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "link_quality: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 2
fi
work=$(mktemp -d /tmp/fahr-link-quality-XXXXXX)
trap 'rm -rf "$work"' EXIT

# label | three_hosts.sh arguments
cases=(
  "haptic+gateway / FEM, no impairment|--relay"
  "haptic+gateway / FEM, 0.5 ms +-1 ms|--link h1-h2:delay_ms=0.5,jitter_ms=1"
  "haptic+gateway / FEM, 2 ms +-1 ms|--link h1-h2:delay_ms=2,jitter_ms=1"
  "haptic+gateway / FEM, 5 ms +-1 ms|--link h1-h2:delay_ms=5,jitter_ms=1"
  "haptic+gateway / FEM, 1 % loss|--link h1-h2:loss=0.01"
  "haptic+gateway / FEM, 5 % loss|--link h1-h2:loss=0.05"
  "gateway / haptic / FEM, no impairment|--relay --gateway-apart"
  "gateway / haptic / FEM, gateway-haptic 0.5 ms|--link h1-h3:delay_ms=0.5 --gateway-apart"
  "gateway / haptic / FEM, gateway-haptic 2 ms +-1 ms|--link h1-h3:delay_ms=2,jitter_ms=1 --gateway-apart"
)

status=0
: >"$work/out.md"
for vendor in $vendors; do
table="$work/table.md"
details="$work/details.md"
{
  echo "### $vendor"
  echo
  echo "$vendor on every service, ${seconds} s a run, services at nice -$nice_level, the 1 kHz ticks SCHED_FIFO, the relay SCHED_FIFO."
  echo "Motion to force: the gateway's whole run, p99. Step: force change per servo tick, p99.9 and max (ticks > 0.1 N)."
  echo "Age: FEM state age at use p99 and ticks on a state > 3 FEM periods old; behind: ticks on a state with > 3 newer ones written."
  echo
  echo "| split, link | load | m2f p99 ms | step p99.9 / max N (> 0.1 N) | age p99 ms | age > 3 periods | > 3 behind | FEM states used / written | stale ContactSets | deadline misses FEM / haptic / gateway | haptic Hz | PC removed mJ | usable |"
  echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"
} >"$table"
: >"$details"
i=0
for c in "${cases[@]}"; do
  i=$((i + 1))
  [ -n "$only" ] && [[ "$only" != *" $i "* ]] && continue
  label=${c%%|*}
  args=${c#*|}
  load=$(cut -d' ' -f1 /proc/loadavg)
  report="$work/$vendor-run$i.md"
  echo "link_quality: $label ($vendor, load $load)" >&2
  # shellcheck disable=SC2086
  if ! bash "$repo/tests/lab/three_hosts.sh" "$build" "$vendor" "$vendor" "$vendor" "$seconds" \
      "$report" $args --nice "$nice_level" --rt >"$work/$vendor-run$i.out" 2>&1; then
    status=1
    echo "link_quality: the run '$label' failed:" >&2
    tail -n 8 "$work/$vendor-run$i.out" >&2
  fi
  if [ ! -s "$report" ]; then
    echo "| $label | $load | run failed | | | | | | | | | | no |" >>"$table"
    continue
  fi
  m2f=$(grep -o "whole run n=[0-9]* p50 [0-9.]* ms p99 [0-9.]*" "$report" | awk '{ print $NF }')
  step=$(grep "force step per servo tick" "$report" | sed -n 's/.*p99.9 \([0-9.]*\) N  max \([0-9.]*\) N  ticks > 0.1 N \([0-9]*\) (\([0-9.]*\) %).*/\1 \2 \3 \4/p')
  age=$(grep "FEM state age at use" "$report" | sed -n 's/.*p99 \([0-9.]*\) ms .*> 3 periods ([0-9.]* ms) [0-9]* (\([0-9.]*\) %).*/\1 \2/p')
  behind=$(grep "newer FEM states written" "$report" | sed -n 's/.*> 3 behind [0-9]* (\([0-9.]*\) %).*/\1/p')
  states=$(grep "FEM states written while" "$report" | sed -n 's/.*were \([0-9]*\), used by a ForceCommand \([0-9]*\).*/\2 \1/p')
  stale=$(grep "^- FEM:" "$report" | sed -n 's/.*stale contact sets \([0-9]*\).*/\1/p')
  misses=$(awk -F'|' '$2 ~ /^ (fem|haptic|device_gateway) / { gsub(/ /, "", $2); gsub(/ /, "", $10); m[$2] = $10 }
    END { printf "%s / %s / %s", m["fem"], m["haptic"], m["device_gateway"] }' "$report")
  hz=$(awk -F'|' '$2 ~ /^ haptic / { gsub(/ /, "", $5); print $5 }' "$report")
  pc=$(grep -o "PC removed [0-9.]* mJ" "$report" | awk '{ print $3 }')
  read -r step_p999 step_max step_n _ <<<"${step:-nan nan 0 0}"
  read -r age_p99 age_pct <<<"${age:-nan nan}"
  read -r used written <<<"${states:-0 0}"
  usable=$(awk -v m="${m2f:-99}" -v s="$step_p999" -v b="${behind:-100}" 'BEGIN {
    why = ""
    if (m > 3) why = why "m2f "
    if (s > 0.100001) why = why "step "
    if (b >= 1) why = why "behind "
    print (why == "" ? "yes" : "no (" substr(why, 1, length(why) - 1) ")") }')
  echo "| $label | $load | ${m2f:-?} | $step_p999 / $step_max ($step_n) | $age_p99 | $age_pct % | ${behind:-?} % | $used / $written | ${stale:-?} | $misses | ${hz:-?} | ${pc:-?} | $usable |" >>"$table"
  {
    echo "##### $label ($vendor)"
    echo
    sed -n '3,$p' "$report"
    echo
  } >>"$details"
done
{
  cat "$table"
  echo
  echo "#### Each run on $vendor"
  echo
  cat "$details"
} >>"$work/out.md"
done
cat "$work/out.md"
if [ ${#markdown[@]} -gt 0 ]; then
  "$results" lab-link-quality "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}" <"$work/out.md"
fi
exit "$status"
