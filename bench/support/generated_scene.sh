#!/usr/bin/env bash
# Writes to stdout the shipped scene pointed at the meshes the scene
# generator wrote into DIR (fahr_scene_generator --out DIR > DIR/generator.log),
# with the glottic opening the generator printed there (its "glottic_view"
# line); --without-epiglottis leaves the epiglottis out (as a blade that has
# lifted it out of the line of sight would leave the view).
#
#   generated_scene.sh DIR [--without-epiglottis] > OUT.yaml
set -euo pipefail
dir="${1:?usage: generated_scene.sh DIR [--without-epiglottis]}"
drop=""
[ "${2:-}" = --without-epiglottis ] && drop=out
repo=$(cd "$(dirname "$0")/../.." && pwd)
opening=$(grep '^glottic_view ' "$dir/generator.log") ||
  { echo "generated_scene: no glottic_view line in $dir/generator.log" >&2; exit 1; }
awk -v dir="$(cd "$dir" && pwd)/" -v opening="$opening" -v drop="$drop" '
  BEGIN { n = split(opening, f, " ")
          for (i = 2; i < n; i++) if (f[i] ~ /^opening_/) { key = f[i]; val = f[i + 1]
            for (j = i + 2; j <= n && f[j] !~ /^opening_/; j++) val = val " " f[j]
            set[key] = val } }
  { gsub(/\.\.\/\.\.\/meshes\/neonatal\//, dir) }
  drop == "out" && /^  - name: epiglottis$/ { skipping = 1; next }
  skipping && /^  - name: / { skipping = 0 }
  skipping { next }
  match($0, /^  (opening_[a-z_]+): /) { key = substr($0, 3, RLENGTH - 4)
    if (key in set) { print "  " key ": " set[key]; next } }
  { print }' "$repo/deployment/scenes/neonatal_intubation.yaml"
