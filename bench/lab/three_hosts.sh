#!/usr/bin/env bash
# The lab station across three network namespaces (tests/lab/three_hosts.sh:
# gateway + haptic on one, FEM on a second, logger + summary on a third,
# multicast dropped) for S seconds on each vendor and both mixes; prints each
# run's rates, motion-to-force, stale ContactSets, FEM states used, per-topic
# loss from the recording, discovery time and the second station's count.
#
#   bench/lab/three_hosts.sh [BUILD_DIR] [--seconds 60] [--markdown [FILE]]
#
# --markdown: also write the output under the bench header (machine, command,
# commit, date) to FILE, by default bench/results/<machine>/lab-three-hosts.md.
# Needs root. About S + 20 s per run, four runs.
set -euo pipefail
load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
seconds=60
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "three_hosts: unknown flag '$1'" >&2; exit 2 ;;
    *) build="$1"; shift ;;
  esac
done
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "three_hosts: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 2
fi
out=$(mktemp /tmp/fahr-lab-bench-XXXXXX.md)
trap 'rm -f "$out"' EXIT
status=0
for mix in "cyclonedds cyclonedds cyclonedds" "fastdds fastdds fastdds" \
           "fastdds cyclonedds fastdds" "cyclonedds fastdds cyclonedds"; do
  # shellcheck disable=SC2086
  bash "$repo/tests/lab/three_hosts.sh" "$build" $mix "$seconds" "$out" >/dev/null 2>"$out.err" ||
    { status=1; echo "three_hosts: the run $mix failed:" >&2; tail -n 5 "$out.err" >&2; }
  echo >>"$out"
done
rm -f "$out.err"
cat "$out"
if [ ${#markdown[@]} -gt 0 ]; then
  "$results" lab-three-hosts "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}" <"$out"
fi
exit "$status"
