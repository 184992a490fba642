#!/usr/bin/env bash
# Writes to stdout the scene SCENE with its hyoid let go: the tongue's fixed
# nodes on the hyoid are freed (written to FIXED_OUT, which the new scene
# names), and the rigid body 'hyoid' and its anatomy pair with the tongue are
# left out. A real hyoid hangs in muscle and moves with the tongue's base;
# without a model of its suspension (docs/design/neonatal-scene.md, open
# questions) the floor behind the mandible then hangs free: an upper bound
# of how far the tongue's base gives way, for benches only.
#
# The hyoid's nodes are the fixed nodes behind x = -36.5 mm: the generator's
# mandible ends at x -35 mm and its hyoid begins at x -38 mm (defaults of
# tools/scene_generator). SCENE must name its meshes with absolute paths (as
# generated_scene.sh and soft_epiglottis_scene.sh write them).
#
#   suspended_hyoid_scene.sh SCENE FIXED_OUT > OUT.yaml
set -euo pipefail
scene="${1:?usage: suspended_hyoid_scene.sh SCENE FIXED_OUT}"
fixed_out="${2:?usage: suspended_hyoid_scene.sh SCENE FIXED_OUT}"
# The tongue's mesh and fixed-nodes file: the first body's.
mesh=$(awk '/^    mesh: / { print $2; exit }' "$scene")
fixed=$(awk '/^      nodes_file: / { print $2; exit }' "$scene")
case "$mesh" in
  /*.node) ;;
  *) echo "suspended_hyoid_scene: $scene: the first body's mesh is not an absolute .node path" >&2
     exit 1 ;;
esac
[ -f "$fixed" ] || { echo "suspended_hyoid_scene: $scene: no fixed-nodes file '$fixed'" >&2; exit 1; }
# TetGen .node: a header line, then "index x y z"; '#' starts a comment.
awk -v limit=-36.5 '
  FNR == NR {
    sub(/#.*/, "")
    if (NF == 0) next
    if (!header) { header = 1; next }
    x[$1] = $2
    next
  }
  {
    sub(/#.*/, "")
    if (NF == 0) next
    if (!($1 in x)) { print "node " $1 " is not in the mesh" > "/dev/stderr"; exit 3 }
    if (x[$1] > limit) print $1; else freed++
  }
  END { if (!freed) { print "no fixed node behind x " limit " mm" > "/dev/stderr"; exit 3 } }
' "$mesh" "$fixed" > "$fixed_out" ||
  { echo "suspended_hyoid_scene: cannot free the hyoid's nodes of $fixed" >&2; exit 1; }
awk -v fixed="$fixed" -v out="$fixed_out" '
  /^  - name: / { in_hyoid = ($0 == "  - name: hyoid") }
  /^[a-z_]+:/ { in_hyoid = 0 }
  in_hyoid { found = 1; next }
  /^    - \[tongue, hyoid\]/ { next }
  /^      nodes_file: / && $2 == fixed && !done { sub(/: .*/, ": " out); done = 1 }
  { print }
  END { if (!found || !done) exit 3 }
' "$scene" || { echo "suspended_hyoid_scene: no body 'hyoid' or no tongue fixed-nodes line in $scene" >&2; exit 1; }
