#!/usr/bin/env bash
# The overshoot on the neonatal tongue across the choices that decide it:
# the tongue's Young's modulus, the FEM's anatomy support springs, whether
# the tool stops at bone and the tongue's compression stiffening (Yeoh
# C20/C10; 0: off, 0.47: the tongue's fit, libs/fem material.cpp). One force-aware run per line (about 75 s each on
# this machine), one Markdown table at the end.
#   bash bench/overshoot/sweep.sh [BUILD_DIR] [--quick]
# --quick: only the shipped modulus, with and without the support springs,
# each with and without stiffening.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build="${1:-$root/build}"
bench="$build/bench/overshoot/fahr_overshoot_bench"
[ -x "$bench" ] || { echo "sweep.sh: no $bench (build the fahr_overshoot_bench target)" >&2; exit 2; }
quick=false
[ "${2:-}" = "--quick" ] && quick=true

# E Pa | support ratio | tool stops (scene = the shipped scene's choice, off) | stiffening C20/C10
configs=("10000 0 scene 0" "10000 100 scene 0" "10000 0 scene 0.47" "10000 100 scene 0.47")
if ! $quick; then
  configs+=("30000 0 scene 0" "30000 100 scene 0" "100000 0 scene 0" "100000 100 scene 0" "10000 100 on 0"
            "100000 100 on 0" "100000 100 scene 0.47" "10000 100 on 0.47")
fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
field() {  # the force-aware column of a table row
  grep -F "| $1 |" "$2" | head -1 | awk -F'|' '{gsub(/^ +| +$/, "", $3); print $3}'
}
echo "| E kPa | support | tool stops | stiffening | most inverted tets | reaction / limit while lost track, FEM side | lost-track ticks | Green strain 1x / end | gap error mm | re-engagement step N (bound) | tongue 1 s after: from rest / from where found mm | --check |"
echo "|---:|---:|---|---:|---:|---:|---:|---|---:|---|---:|---|"
for config in "${configs[@]}"; do
  read -r youngs support stops stiffening <<<"$config"
  file="$out/$youngs-$support-$stops-$stiffening.txt"
  verdict=pass
  "$bench" --response force-aware --youngs-pa "$youngs" --fem-support "$support" --tool-stops "$stops" \
    --stiffening "$stiffening" --check \
    >"$file" 2>&1 || verdict=fail
  echo "| $((youngs / 1000)) | $support | $stops | $stiffening | $(field "most inverted tets" "$file") |" \
       "$(field "largest reaction / limit while lost track, FEM side" "$file") | $(field "lost-track ticks" "$file") |" \
       "$(field "largest principal Green strain at 1x / at the end of the hold" "$file") |" \
       "$(field "largest published-gap error mm (lost-track ticks at the peak limit)" "$file") |" \
       "$(field "largest force step in 50 ms of re-engagement N (bound)" "$file") |" \
       "$(field "tongue 1 s after the blade left: from rest / from where the blade found it mm" "$file") | $verdict |"
done
