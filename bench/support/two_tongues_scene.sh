#!/usr/bin/env bash
# Writes to stdout the scene SCENE with a copy of its body 'tongue' as a
# second deformable body: 'tongue_b', id 2, 1 mm superior (+y), both under
# the blade. A case of several deformable bodies for tests and benches (two
# overlapping tongues: the mechanism, not anatomy). Mesh paths become
# absolute, so the file may live anywhere; comments of the copied block are
# dropped.
#
#   two_tongues_scene.sh SCENE > OUT.yaml
set -euo pipefail
scene="${1:?usage: two_tongues_scene.sh SCENE}"
dir=$(cd "$(dirname "$scene")" && pwd)
awk -v dir="$dir/" '
  # Relative mesh and nodes paths: made absolute.
  /^ *(mesh|nodes_file): / && $2 !~ /^\// { sub(/: /, ": " dir) }
  /^  - name: / { in_tongue = ($0 == "  - name: tongue") }
  in_tongue && !/^ *#/ { copy = copy $0 "\n" }
  !in_tongue && copy != "" && !done {
    sub(/- name: tongue\n/, "- name: tongue_b\n", copy)
    sub(/\n    id: 1\n/, "\n    id: 2\n", copy)
    sub(/position_m: \[0\.0, 0\.0, 0\.0\]/, "position_m: [0.0, 0.001, 0.0]", copy)
    printf "%s", copy
    done = 1
  }
  { print }
  END { if (!done) exit 3 }
' "$scene" || { echo "two_tongues_scene: no body 'tongue' with a block after it in $scene" >&2; exit 1; }
