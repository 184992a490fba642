#!/usr/bin/env bash
# The glottic view score (libs/glottic_view) on the shipped scene, by lines
# of sight and by a pixel count of the same view (fahr_glottic_score): the
# blade's suggested poses from the scene's eye, a sweep of eyes around the
# opening that sees all, part and none of it, what the rigid anatomy alone
# lets through from the mouth's side, the grid of blade poses the
# laryngoscopist could hold, and (with --recording) a recorded run's rest,
# best and last view; the wall time of a score; the pictures.
#
#   bench/glottic_view/glottic_view.sh [BUILD_DIR] [--recording RUN.mcap | --run S]
#       [--pictures DIR] [--markdown [FILE]]
#
# --run S: record S simulated seconds of the intubation in lockstep first
# (deployment/run_local.sh --record; about 4 s of wall time per second) and
# score that recording.
# --pictures DIR: the laryngoscopist's views as PNG (the opening in green).
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/glottic-view.md. About 30 s.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
recording=""
run_s=""
pictures=""
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --recording) recording="$2"; shift 2 ;;
    --run) run_s="$2"; shift 2 ;;
    --pictures) pictures="$2"; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -*) echo "glottic_view: unknown flag $1" >&2; exit 2 ;;
    *) build=$(cd "$1" && pwd); shift ;;
  esac
done
tool="$build/tools/glottic_score/fahr_glottic_score"
[ -x "$tool" ] || { echo "glottic_view: build fahr_glottic_score first" >&2; exit 1; }
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "glottic_view: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 1
fi
[ -z "$pictures" ] || mkdir -p "$pictures"
work=$(mktemp -d /tmp/fahr-glottic-view-XXXXXX)
trap 'rm -rf "$work"' EXIT
if [ -n "$run_s" ]; then
  recording="$work/intubation_lockstep_${run_s}s.mcap"
  bash "$repo/deployment/run_local.sh" "$build" --mode lockstep --duration-s "$run_s" \
    --record "$recording" >"$work/run.log" 2>&1 || { cat "$work/run.log" >&2; exit 1; }
fi

# "view L: rays R % (s/n samples, T ms), pixels P % (v/t), difference D points; eye (..) mm"
row() {
  perl -ne 'print "| $1 | ($6) | $2 | $4 | $5 | $3 |\n" if /^view ([^:]*): rays ([0-9.]+) % \(\d+\/\d+ samples, ([0-9.]+) ms\), pixels ([0-9.]+) % \(\d+\/\d+\), difference ([0-9.]+) points; eye \((.*)\) mm$/'
}
{
  echo "## Blade poses, seen from the scene's eye on the blade, the tongue at rest"
  echo
  echo "| view | eye, world mm | rays % | pixels % | difference, points | score ms |"
  echo "| --- | --- | ---: | ---: | ---: | ---: |"
  # The presets, and the best pose of the grid below (tip 50 mm in, 12 mm
  # down, pitched 40 deg: the blade through the rest tongue). Its eye is
  # 257 mm above the oral axis and looks down past the palate block: the
  # scene has no skull or nose there, so this is not a view through the
  # mouth, but it has the blade in the line of sight, partly.
  for pose in initial pressing -50,-12,0,40; do
    png=()
    [ -z "$pictures" ] || png=(--png "$pictures/eye_${pose//,/_}.png")
    "$tool" --pose "$pose" "${png[@]}" | grep '^view' | row
  done
  echo
  echo "## Eyes 20 mm from the opening, turned from its normal towards the mouth (mid-sagittal, 4 mm aside)"
  echo
  echo "| turned, deg | eye, world mm | rays % | pixels % | difference, points | score ms |"
  echo "| --- | --- | ---: | ---: | ---: | ---: |"
  for deg in -70 -40 -10 0 10 14 17 19 21 30; do
    "$tool" --around "$deg,20,4" | grep '^view' | row | sed -E "s/^\| scene \|/| $deg |/"
  done
  echo
  echo "## The rigid anatomy alone (no tongue, no blade), rays only: eyes turned from the opening's normal towards the mouth"
  echo
  echo "A line from the glottis through the mouth opening is turned 52-57 deg; the eyes at 150 and 300 mm on it lie beyond the lips."
  echo
  echo "| turned, deg | 40 mm | 150 mm | 300 mm |"
  echo "| ---: | ---: | ---: | ---: |"
  for deg in 0 10 20 35 45 55; do
    line="| $deg |"
    for mm in 40 150 300; do
      r=$("$tool" --anatomy-only --around "$deg,$mm,0" --samples 256 | sed -E 's/.*rays ([0-9.]+) %.*/\1/')
      line="$line $r |"
    done
    echo "$line"
  done
  echo
  echo "## Blade poses: tip (x, y) mm and pitch, the tongue at rest, rays only"
  echo
  echo "| pitch, deg | tip x -20, y -5 | -20, -12 | -35, -5 | -35, -12 | -50, -5 | -50, -12 |"
  echo "| ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
  for pitch in 0 10 20 30 40; do
    line="| $pitch |"
    for tip in "-20,-5" "-20,-12" "-35,-5" "-35,-12" "-50,-5" "-50,-12"; do
      r=$("$tool" --pose "$tip,0,$pitch" --samples 256 | sed -E 's/.*rays ([0-9.]+) %.*/\1/')
      line="$line $r |"
    done
    echo "$line"
  done
  if [ -n "$recording" ]; then
    echo
    echo "## A recorded run: $(basename "$recording")"
    echo
    echo "| view | eye, world mm | rays % | pixels % | difference, points | score ms |"
    echo "| --- | --- | ---: | ---: | ---: | ---: |"
    prefix=()
    [ -z "$pictures" ] || prefix=(--png-prefix "$pictures/run")
    "$tool" --recording "$recording" "${prefix[@]}" | tee "$work/run.txt" | grep '^view' | row
    echo
    grep '^fahr_glottic_score' "$work/run.txt" || true
  fi
} | if [ ${#markdown[@]} -gt 0 ]; then
  # It copies the tables to stdout as they come, so its wall time is the run's.
  "$results" glottic-view "${markdown[@]}" -- "${command[@]}"
else
  cat
fi
