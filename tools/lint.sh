#!/usr/bin/env bash
# Lint of fahr's own C++: clang-format (.clang-format) on every tracked C++ file, then
# clang-tidy (.clang-tidy, every finding an error) on every translation unit of ours in a
# build directory's compile_commands.json; a header is checked through the units that include
# it (the header filter covers our folders, not /usr nor the generated IDL bindings).
#
#   tools/lint.sh [BUILD_DIR] [--changed-since REF] [--format-only | --tidy-only] [--jobs N]
#                 [--list]
#
# BUILD_DIR (default build/) must be configured (CMake writes compile_commands.json) and its
# IDL bindings generated (a build of any target that links fahr::idl, or the whole build).
# --changed-since REF: clang-tidy only on the units changed since REF (committed or not) and
# on the units that include a changed header; clang-format still checks every file (it is
# fast). --changed-since lint-base takes REF from .lint-base: the newest commit that touched
# it, when the whole tree was last clean (see .lint-base).
# --list: print the units clang-tidy would check, and stop.
# Prints file:line:col of each finding and exits non-zero when there is any.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build"
changed_since=""
do_format=1
do_tidy=1
list_only=0
jobs=$(nproc 2>/dev/null || echo 2)
while [ $# -gt 0 ]; do
  case "$1" in
    --changed-since) changed_since="${2:?--changed-since needs a git revision}"; shift 2 ;;
    --format-only) do_tidy=0; shift ;;
    --tidy-only) do_format=0; shift ;;
    --jobs) jobs="${2:?--jobs needs a number}"; shift 2 ;;
    --list) list_only=1; do_format=0; shift ;;
    -h | --help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "lint: unknown option $1" >&2; exit 2 ;;
    *) build=$(cd "$1" && pwd); shift ;;
  esac
done
cd "$root"
status=0

# Every C++ file we own is tracked by git under these folders (idl/ holds IDL, not C++).
owned_dirs=(libs services sim bench tools tests)
cpp_pathspec=()
for d in "${owned_dirs[@]}"; do
  for e in cpp h hpp cc; do cpp_pathspec+=("$d/*.$e"); done
done

if [ "$do_format" -eq 1 ]; then
  command -v clang-format >/dev/null || { echo "lint: clang-format not found (tools/setup.sh)" >&2; exit 2; }
  mapfile -t files < <(git ls-files -- "${cpp_pathspec[@]}")
  format_log=$(mktemp)
  # -Werror makes each difference an error naming file:line:col.
  if ! printf '%s\0' "${files[@]}" | xargs -0 -n 32 -P "$jobs" clang-format --dry-run -Werror \
    >"$format_log" 2>&1; then
    grep -E '^[^ ].*:[0-9]+:[0-9]+: error' "$format_log" | sed "s|^$root/||" || true
    count=$(grep -cE ':[0-9]+:[0-9]+: error' "$format_log" || true)
    echo "lint: clang-format: $count difference(s) in" \
      "$(grep -E ':[0-9]+:[0-9]+: error' "$format_log" | cut -d: -f1 | sort -u | wc -l) file(s);" \
      "fix with: clang-format -i FILE"
    status=1
  else
    echo "lint: clang-format: ${#files[@]} files clean"
  fi
  rm -f "$format_log"
fi

if [ "$do_tidy" -eq 0 ]; then
  exit "$status"
fi

command -v clang-tidy >/dev/null || { echo "lint: clang-tidy not found (tools/setup.sh)" >&2; exit 2; }
db="$build/compile_commands.json"
[ -f "$db" ] || { echo "lint: no $db; configure a build first (cmake -S . -B build)" >&2; exit 2; }

# Our translation units: the database's files under the owned folders of this checkout (not
# the generated bindings in the build directory, wherever it lies).
owned_regex="^$root/($(IFS='|'; echo "${owned_dirs[*]}"))/"
mapfile -t units < <(sed -n 's/^ *"file": "\(.*\)",\{0,1\}$/\1/p' "$db" | grep -E "$owned_regex" |
  sort -u)

if [ -n "$changed_since" ]; then
  if [ "$changed_since" = lint-base ]; then
    changed_since=$(git log -1 --format=%H -- .lint-base 2>/dev/null || true)
  fi
  if [ -z "$changed_since" ] || ! git rev-parse -q --verify "$changed_since^{commit}" >/dev/null; then
    echo "lint: no base commit to compare with (shallow clone?); checking the whole tree"
  else
    # Committed since the base, changed in the work tree, and new untracked files.
    mapfile -t changed < <({
      git diff --name-only --diff-filter=d "$changed_since" -- "${cpp_pathspec[@]}"
      git ls-files --others --exclude-standard -- "${cpp_pathspec[@]}"
    } | sort -u)
    declare -A wanted=()
    declare -A in_db=()
    for u in "${units[@]}"; do in_db["$u"]=1; done
    for f in "${changed[@]}"; do
      case "$f" in
        *.cpp | *.cc) [ -n "${in_db[$root/$f]:-}" ] && wanted["$root/$f"]=1 ;;
        *)
          # A header: the units that include it by a path it ends with (its own .cpp, the
          # tests); through the headers that include it when no unit does directly.
          frontier=("$f")
          seen=" $f "
          for _ in 1 2 3 4; do
            next=()
            for h in "${frontier[@]}"; do
              base=$(basename "$h")
              while IFS= read -r inc; do
                file=${inc%%:*}
                path=$(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' <<<"${inc#*:}")
                case "$h" in */"$path" | "$path") ;; *) continue ;; esac
                case "$file" in
                  *.cpp | *.cc) [ -n "${in_db[$root/$file]:-}" ] && wanted["$root/$file"]=1 ;;
                  *) [[ "$seen" == *" $file "* ]] || { seen+="$file "; next+=("$file"); } ;;
                esac
              done < <(git grep -E "#[[:space:]]*include[[:space:]]*\"([^\"]*/)?$base\"" \
                -- "${cpp_pathspec[@]}" || true)
            done
            found=0
            for u in "${!wanted[@]}"; do found=1; break; done
            [ "$found" -eq 1 ] || [ ${#next[@]} -eq 0 ] && break
            frontier=("${next[@]}")
          done
          ;;
      esac
    done
    units=()
    for u in "${!wanted[@]}"; do units+=("$u"); done
    echo "lint: clang-tidy on the units changed since ${changed_since:0:12}" \
      "(${#changed[@]} C++ file(s) changed, ${#units[@]} unit(s) to check)"
  fi
fi

if [ "$list_only" -eq 1 ]; then
  [ ${#units[@]} -eq 0 ] || printf '%s\n' "${units[@]}" | sed "s|^$root/||" | sort
  exit 0
fi
if [ ${#units[@]} -eq 0 ]; then
  echo "lint: clang-tidy: nothing to check"
  exit "$status"
fi

logs=$(mktemp -d /tmp/fahr-lint-XXXXXX)
start=$(date +%s)
# One log per unit, so parallel runs do not interleave; the header filter is anchored at this
# checkout (the .clang-tidy one matches our folders under any root, for editors).
header_filter="^$root/($(IFS='|'; echo "${owned_dirs[*]}"))/"
printf '%s\0' "${units[@]}" | xargs -0 -P "$jobs" -I{} sh -c \
  'clang-tidy -p "$1" --quiet --header-filter="$2" "$3" >"$4/$(echo "$3" | tr / _).log" 2>&1 || true' \
  _ "$build" "$header_filter" {} "$logs"
elapsed=$(($(date +%s) - start))

# A header's finding appears once per unit that includes it: count each once.
findings=$(cat "$logs"/*.log | grep -E '^/.*:[0-9]+:[0-9]+: (warning|error): ' |
  sed "s|^$root/||" | sort -u || true)
if [ -n "$findings" ]; then
  echo "$findings"
  echo "lint: clang-tidy: $(wc -l <<<"$findings") finding(s) in ${#units[@]} unit(s), ${elapsed} s;" \
    "per check:"
  sed -n 's/.*\[\([^]]*\)\]$/\1/p' <<<"$findings" | sed 's/,-warnings-as-errors//' | sort |
    uniq -c | sort -rn
  echo "lint: each unit's full output (notes, fix-its) is in $logs"
  status=1
else
  echo "lint: clang-tidy: ${#units[@]} unit(s) clean, ${elapsed} s"
  rm -rf "$logs"
fi
exit "$status"
