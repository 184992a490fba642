#!/usr/bin/env bash
# The cost of a second deformable body: the whole loop in one process
# (fahr_stack_sim_run, lockstep, the intubation script) on the shipped scene
# on the same scene with its epiglottis made a deformable body
# (bench/support/soft_epiglottis_scene.sh: the intubation's blade does not
# reach it) and with a copy of the tongue 1 mm above it
# (bench/support/two_tongues_scene.sh: both under the blade), one after the
# other in one run. Per scene: the peak force, the FEM period's CPU (every
# body's step and background factorisation), the haptic tick's CPU, and per
# body how long the blade touched it and how far it moved. Timings compare
# only within one run.
#
#   bench/two_bodies/two_bodies.sh [BUILD_DIR] [--seconds S] [--markdown [FILE]]
#
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/two-deformable-bodies.md. About 3 min
# for the default 4 s on the 2-core station.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
seconds=4
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=${2:?--seconds needs a value}; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -*) echo "two_bodies: unknown flag $1" >&2; exit 2 ;;
    *) build=$(cd "$1" && pwd); shift ;;
  esac
done
run="$build/sim/stack_sim_run/fahr_stack_sim_run"
[ -x "$run" ] || { echo "two_bodies: build fahr_stack_sim_run first" >&2; exit 1; }
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "two_bodies: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 1
fi
# The kernels the lockstep figures repeat with (bench/README.md).
export OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-Haswell} OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
work=$(mktemp -d /tmp/fahr-two-bodies-XXXXXX)
trap 'rm -rf "$work"' EXIT
shipped="$repo/deployment/scenes/neonatal_intubation.yaml"
bash "$repo/bench/support/two_tongues_scene.sh" "$shipped" >"$work/two.yaml"
bash "$repo/bench/support/soft_epiglottis_scene.sh" "$shipped" >"$work/leaf.yaml"
"$run" --seconds "$seconds" --scene "$shipped" >"$work/one.txt"
"$run" --seconds "$seconds" --scene "$work/leaf.yaml" >"$work/leaf.txt"
"$run" --seconds "$seconds" --scene "$work/two.yaml" >"$work/two.txt"

field() { sed -nE "s/$2/\1/p" "$1" | head -n 1; }
{
  echo "## One deformable body against two, ${seconds} s of the intubation script in one process"
  echo
  echo "The FEM period's CPU is every body's step and its background factorisation; the tick's"
  echo "is the haptic tick alone (thread CPU, no digest). Wall time: the whole run."
  echo
  echo "| scene | wall s | peak F N | FEM period CPU ms p50 | p99 | max | haptic tick CPU us p50 | p99 | p99.9 | rows per tick p99 |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
  for case in one leaf two; do
    f="$work/$case.txt"
    case "$case" in
      one) name="tongue (shipped)" ;;
      leaf) name="tongue + soft epiglottis" ;;
      two) name="tongue + tongue_b" ;;
    esac
    echo "| $name | $(field "$f" '^stack_sim: [0-9]+ steps, ([0-9.]+) s wall.*') \
| $(field "$f" '.*peak \|F\| ([0-9.]+) N.*') \
| $(field "$f" '^FEM step CPU ms median ([0-9.]+) p99.*') \
| $(field "$f" '^FEM step CPU ms median [0-9.]+ p99 ([0-9.]+) max.*') \
| $(field "$f" '^FEM step CPU ms median [0-9.]+ p99 [0-9.]+ max ([0-9.]+).*') \
| $(field "$f" '^stack_sim: haptic tick CPU us median ([0-9]+) .*') \
| $(field "$f" '^stack_sim: haptic tick CPU us median [0-9]+ p99 ([0-9]+) .*') \
| $(field "$f" '^stack_sim: haptic tick CPU us .* p99.9 ([0-9]+) .*') \
| $(field "$f" '^stack_sim: rows per tick p50 [0-9]+ p99 ([0-9]+) .*') |"
  done
  echo
  echo "## Per body, the two-body runs"
  echo
  echo "| body | ticks with tool contacts | most in one set | largest node motion mm | sets refused (layout, unknown sphere) |"
  echo "| --- | ---: | ---: | ---: | --- |"
  sed -nE "s/^stack_sim: body '([^']+)': ticks with tool contacts ([0-9]+), most in one set ([0-9]+), largest node motion ([0-9.]+) mm, ContactSets refused: layout ([0-9]+), unknown sphere ([0-9]+);.*/| \1 | \2 | \3 | \4 | \5, \6 |/p" \
    "$work/leaf.txt" "$work/two.txt"
  echo
  echo "The two-body runs' output hashes (as fahr_lockstep_clock prints them over DDS):"
  echo
  for case in leaf two; do
    echo "- $case: $(sed -n 's/^lockstep_clock: hash \(.*\)/\1/p' "$work/$case.txt" | paste -sd ',' | sed 's/,/, /g')"
  done
} | if [ ${#markdown[@]} -gt 0 ]; then
  "$results" two-deformable-bodies "${markdown[@]}" -- "${command[@]}"
else
  cat
fi
