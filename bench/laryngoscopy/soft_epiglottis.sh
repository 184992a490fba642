#!/usr/bin/env bash
# The epiglottis as a second deformable body, on the shipped airway (head
# neutral) and on the airway placed for laryngoscopy (head extended 15 deg,
# the larynx's anterior rim 5 mm lowered, generated into a temporary
# directory: the shipped files are not touched): per airway, the whole loop
# in lockstep in one process (fahr_laryngoscopy_bench) with the shipped
# intubation script and with the Miller keyframes tried on it
# (miller_neutral.keyframes, miller_extended.keyframes), the extended airway
# once more with the mouth opened wider and the hyoid let go
# (miller_open.keyframes) and then with the larynx raised 6 mm as well
# (miller_raised.keyframes), with two wrong techniques beside it (the handle
# rocked back, miller_levering.keyframes; the tip stopped short of the
# epiglottis, miller_shallow.keyframes), and the neutral Miller keyframes once more
# without the blade's contact with the lips; first,
# how far the tongue and the epiglottis at rest reach above the lines of
# sight to the glottis. Each run prints the blade's force on each body, their
# motion and the glottic view every 0.5 s, then the peaks.
#
#   bench/laryngoscopy/soft_epiglottis.sh [BUILD_DIR] [--markdown [FILE]]
#
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/soft-epiglottis.md. About 5 min.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
markdown=()
while [ $# -gt 0 ]; do
  case "$1" in
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -*) echo "soft_epiglottis: unknown flag $1" >&2; exit 2 ;;
    *) build=$(cd "$1" && pwd); shift ;;
  esac
done
bench="$build/bench/laryngoscopy/fahr_laryngoscopy_bench"
generator="$build/tools/scene_generator/fahr_scene_generator"
for tool in "$bench" "$generator"; do
  [ -x "$tool" ] || { echo "soft_epiglottis: build $(basename "$tool") first" >&2; exit 1; }
done
results="$build/bench/support/fahr_bench_results"
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "soft_epiglottis: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 1
fi
export OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-Haswell} OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
work=$(mktemp -d /tmp/fahr-soft-epiglottis-XXXXXX)
trap 'rm -rf "$work"' EXIT
shipped="$repo/deployment/scenes/neonatal_intubation.yaml"
soft="$repo/bench/support/soft_epiglottis_scene.sh"

# A generated airway: its meshes in DIR, and the shipped scene pointed at
# them (DIR/rigid.yaml).
generate() {
  local dir=$1
  shift
  mkdir -p "$dir"
  "$generator" --out "$dir" "$@" >"$dir/generator.log" 2>&1 ||
    { echo "soft_epiglottis: the generator refused:" >&2; tail -n 20 "$dir/generator.log" >&2; exit 1; }
  bash "$repo/bench/support/generated_scene.sh" "$dir" >"$dir/rigid.yaml"
}
# The extended airway; and the same with the mouth opened wider (the lower
# gum ridge 3.5 mm lower, the lips' opening 20 mm tall), its hyoid let go.
generate "$work/extended" --head-extension-deg 15 --larynx-fold-rise-mm -5
generate "$work/open" --head-extension-deg 15 --larynx-fold-rise-mm -5 --jaw-ridge-y-mm -9 \
  --mouth-half-height-mm 10
# ... and with the larynx raised 6 mm as well.
generate "$work/raised" --head-extension-deg 15 --larynx-fold-rise-mm -5 --jaw-ridge-y-mm -9 \
  --mouth-half-height-mm 10 --larynx-inlet-y-mm -18
bash "$soft" "$shipped" >"$work/neutral.yaml"
bash "$soft" "$work/extended/rigid.yaml" >"$work/extended.yaml"
bash "$soft" "$work/open/rigid.yaml" >"$work/open/soft.yaml"
bash "$repo/bench/support/suspended_hyoid_scene.sh" "$work/open/soft.yaml" \
  "$work/open/fixed_without_hyoid.txt" >"$work/open.yaml"
bash "$soft" "$work/raised/rigid.yaml" >"$work/raised/soft.yaml"
bash "$repo/bench/support/suspended_hyoid_scene.sh" "$work/raised/soft.yaml" \
  "$work/raised/fixed_without_hyoid.txt" >"$work/raised.yaml"
# The neutral airway without the blade's contact with the lips: is the lip
# what stops the blade?
sed 's/^  exclude_pairs: \[\]$/  exclude_pairs: [[miller1, lips_face]]/' "$work/neutral.yaml" \
  >"$work/neutral_without_lips.yaml"
grep -q '^  exclude_pairs: \[\[miller1, lips_face\]\]$' "$work/neutral_without_lips.yaml" ||
  { echo "soft_epiglottis: the shipped scene's exclude_pairs line changed; update this script" >&2; exit 1; }

{
  echo "## The epiglottis as a deformable body"
  echo
  echo "The shipped scene with its epiglottis made soft (bench/support/soft_epiglottis_scene.sh:"
  echo "the generator's tet leaf, fixed at its base, E 1 MPa, an estimate), in lockstep in one"
  echo "process. Neutral: the shipped airway; extended: head extended 15 deg, the larynx's"
  echo "anterior rim 5 mm lowered. Per row: where the blade tip is (world frame), the hand's"
  echo "lead over the blade, the force rendered, and per body the blade's force on it (the sum of"
  echo "its tool rows), its tool rows and its largest node motion; the glottic view from the"
  echo "scene's eye."
  echo
  echo "### What a straight blade must press out of the line of sight"
  echo
  echo "Each deformable body at rest against lines of sight from the glottic opening, turned from"
  echo "its normal towards the mouth (fahr_laryngoscopy_bench --sight-corridor), within 5 mm of the"
  echo "mid-line: the extended airway at the angles whose lines pass the rigid anatomy with the"
  echo "epiglottis out of the way (airway-placement.md: 40 and 45 deg)."
  echo
  echo '```'
  "$bench" --scene "$work/extended.yaml" --sight-corridor 40 45
  echo '```'
  echo
  echo "The same at 40 deg on a paraglossal path: the strip's centre from the glottis to 10 mm"
  echo "right of the mid-line in the mouth's plane (\`--corridor-mouth-z-mm 10\`)."
  echo
  echo '```'
  "$bench" --scene "$work/extended.yaml" --sight-corridor 40 --corridor-mouth-z-mm 10
  echo '```'
  for airway in neutral extended; do
    for motion in intubation "miller_$airway.keyframes"; do
      echo
      echo "### $airway airway, $motion"
      echo
      echo '```'
      if [ "$motion" = intubation ]; then
        "$bench" --scene "$work/$airway.yaml" --script intubation --trace-every 1
      else
        "$bench" --scene "$work/$airway.yaml" --keyframes "$here/$motion" --seconds 12 \
          --trace-every 0.5
      fi
      echo '```'
    done
  done
  echo
  echo "### extended airway, mouth opened wider, hyoid let go, miller_open.keyframes"
  echo
  echo '```'
  "$bench" --scene "$work/open.yaml" --keyframes "$here/miller_open.keyframes" --seconds 13 \
    --trace-every 0.5
  echo '```'
  # The larynx raised as well, with the eye 30 mm above the blade (the
  # scene's eye, 300 mm along the blade and 100 mm above it, looks down over
  # the upper lip on these airways): the Miller lift, then two wrong
  # techniques on the same airway and eye (the handle rocked back behind the
  # epiglottis instead of lifted; the tip stopped in front of it).
  for motion in raised levering shallow; do
    echo
    case "$motion" in
      raised) echo "### the same with the larynx raised 6 mm, the eye 30 mm above the blade, miller_raised.keyframes" ;;
      *) echo "### the same airway and eye, a wrong technique: miller_$motion.keyframes" ;;
    esac
    echo
    echo '```'
    "$bench" --scene "$work/raised.yaml" --keyframes "$here/miller_$motion.keyframes" --seconds 13 \
      --trace-every 0.5 --eye-in-tool-mm 300 30 0
    echo '```'
  done
  echo
  echo "### neutral airway without the blade's contact with the lips, miller_neutral.keyframes"
  echo
  echo '```'
  "$bench" --scene "$work/neutral_without_lips.yaml" --keyframes "$here/miller_neutral.keyframes" \
    --seconds 12 --trace-every 0.5
  echo '```'
} | if [ ${#markdown[@]} -gt 0 ]; then
  "$results" soft-epiglottis "${markdown[@]}" -- "${command[@]}"
else
  cat
fi
