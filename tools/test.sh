#!/usr/bin/env bash
# Sets up the machine, builds fahr and runs the whole test suite:
#   bash tools/test.sh
# FAHR_BUILD_DIR (default build/) and FAHR_WERROR (default ON) adjust it;
# FAHR_FUZZ_SECONDS (default 20) bounds each fuzz target's run.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${FAHR_BUILD_DIR:-$root/build}"

bash "$root/tools/setup.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFAHR_WERROR="${FAHR_WERROR:-ON}"
cmake --build "$build" -j2
# Style: clang-format on every C++ file we own (seconds; a difference fails
# the run after the tests, so one run reports both). clang-tidy over the whole
# tree takes about 20 minutes of both cores: `bash tools/lint.sh` runs it.
lint_status=0
bash "$root/tools/lint.sh" "$build" --format-only --jobs 2 || lint_status=$?
# The dependency rules, on CMake's link graph: no FEM target nor the shared
# runtime reaches the collision library or Bullet, no library a service.
bash "$root/tools/check_deps.sh" "$build"
# Multi-process tests are RUN_SERIAL (they measure timing); the rest share the cores.
ctest --test-dir "$build" --output-on-failure -j2
if [ -x "$root/tools/run_fuzzers.sh" ]; then
  bash "$root/tools/run_fuzzers.sh" "${FAHR_FUZZ_SECONDS:-20}"
fi
if [ "$lint_status" -ne 0 ]; then
  echo "test.sh: tools/lint.sh found clang-format differences (listed above the tests); failing" >&2
  exit "$lint_status"
fi
