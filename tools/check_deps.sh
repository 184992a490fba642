#!/usr/bin/env bash
# Fails when a target depends, directly or through others, on what the
# dependency rules forbid it (docs/architecture.md): the FEM side and the
# libraries the services share never reach the collision library or Bullet
# (the FEM service builds the sphere layout, not the AIST tree), no library
# in libs/ reaches a service, and the physics libraries know no transport.
#
#   bash tools/check_deps.sh [BUILD_DIR]      # default build/
#   bash tools/check_deps.sh --dot FILE       # check a graph already written
#
# With a build dir it writes CMake's link graph first
# (cd BUILD_DIR && cmake --graphviz=g/deps.dot .) and reads g/deps.dot. Every
# edge counts, public, private or interface: a private static dependency is
# still linked in. Prints each forbidden path found, and exits 1 if any.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

if [ "${1:-}" = "--dot" ]; then
  dot="${2:?--dot needs a file}"
else
  build="${1:-$root/build}"
  [ -f "$build/CMakeCache.txt" ] || { echo "check_deps: $build is not a configured build dir" >&2; exit 2; }
  (cd "$build" && cmake --graphviz=g/deps.dot . > /dev/null)
  dot="$build/g/deps.dot"
fi
[ -s "$dot" ] || { echo "check_deps: no graph in $dot" >&2; exit 2; }

# Rules: "roots|forbidden|why". roots: target names separated by spaces;
# forbidden: an extended regular expression over target names (library
# paths for imported ones), matched without regard to case.
rules=$(cat <<'EOF'
fahr_fem fahr_fem_service_core fahr_fem_service fahr_runtime fahr_sphere_layout fahr_layout_links|^fahr_collision$|bullet|the FEM side and the shared runtime build the sphere layout, never the AIST tree or Bullet
fahr_fem fahr_fem_service_core fahr_fem_service|^fahr_haptic_service(_core)?$|the FEM service knows no haptic service
EOF
)
libs=""
for dir in "$root"/libs/*/; do
  [ -f "$dir/CMakeLists.txt" ] && libs="$libs fahr_$(basename "$dir")"
done
rules="$rules
${libs# }|_service(_core)?$|^fahr_stack_sim$|a library in libs/ knows no service
fahr_fem fahr_collision fahr_sphere_layout fahr_geometry fahr_contact fahr_layout_links|^fahr_common$|^fahr_idl_|fastrtps|fastcdr|ddsc|physics libraries know no transport"

awk -v rules="$rules" '
  # Node: "node7" [ label = "fahr_fem\n(fahr::fem)", shape = octagon ];
  /^ *"node[0-9]+" \[ label = / {
    id = $1; gsub(/"/, "", id)
    label = $0; sub(/^[^=]*= "/, "", label); sub(/".*$/, "", label); sub(/\\n.*$/, "", label)
    name[id] = label; by_name[label] = id
    next
  }
  # Edge: "node7" -> "node9" [ style = dotted ] // fahr_fem -> ...
  /^ *"node[0-9]+" -> "node[0-9]+"/ {
    from = $1; to = $3; gsub(/"/, "", from); gsub(/"/, "", to)
    out[from] = out[from] " " to
    next
  }
  END {
    nrules = split(rules, lines, "\n")
    bad = 0; checked = 0
    for (r = 1; r <= nrules; ++r) {
      if (lines[r] == "") continue
      # roots | forbidden (may itself hold "|") | why (after the last "|")
      first = index(lines[r], "|")
      roots = substr(lines[r], 1, first - 1)
      rest = substr(lines[r], first + 1)
      why = rest; sub(/^.*\|/, "", why)
      forbidden = substr(rest, 1, length(rest) - length(why) - 1)
      nroots = split(roots, root_list, " ")
      for (k = 1; k <= nroots; ++k) {
        start = by_name[root_list[k]]
        if (start == "") continue  # not configured (FAHR_ONLY)
        ++checked
        # Breadth-first from the root, remembering how each node was reached.
        delete seen; delete parent
        head = 1; tail = 1; queue[1] = start; seen[start] = 1
        while (head <= tail) {
          node = queue[head++]
          if (node != start && tolower(name[node]) ~ forbidden) {
            path = name[node]
            for (p = parent[node]; p != ""; p = parent[p]) path = name[p] " -> " path
            printf "check_deps: forbidden: %s (%s)\n", path, why
            ++bad
            continue
          }
          n = split(out[node], next_nodes, " ")
          for (j = 1; j <= n; ++j) {
            if (!(next_nodes[j] in seen)) {
              seen[next_nodes[j]] = 1; parent[next_nodes[j]] = node; queue[++tail] = next_nodes[j]
            }
          }
        }
      }
    }
    if (checked == 0) { print "check_deps: no rule root found in the graph"; exit 2 }
    if (bad > 0) { printf "check_deps: %d forbidden dependency path(s)\n", bad; exit 1 }
    printf "check_deps: %d targets checked against %d rules: no forbidden dependency\n", checked, nrules
  }
' "$dot"
