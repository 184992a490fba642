#!/usr/bin/env bash
# Builds the libFuzzer targets of the text mesh loaders with clang
# (ASan + UBSan) in their own build directory and runs each for a bounded
# time from the seed corpora in tests/fuzz/corpus/.
#
# usage: tools/run_fuzzers.sh [seconds per fuzzer, default 20] [build dir, default build-fuzz]
# Exits non-zero when a fuzzer finds a crash, leak or sanitizer report; the
# reproducer is left in the build dir's fuzz-artifacts/.
set -euo pipefail

seconds="${1:-20}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${2:-${root}/build-fuzz}"
targets=(fuzz_tetgen fuzz_gmsh fuzz_vtk)

# tests/ is only added with FAHR_BUILD_TESTS=ON, so it stays ON here; the
# benches are left out. Only the fuzz targets are built, never the suite.
CC=clang CXX=clang++ cmake -S "${root}" -B "${build}" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFAHR_FUZZ=ON -DFAHR_BUILD_TESTS=ON -DFAHR_BUILD_BENCHES=OFF >/dev/null
cmake --build "${build}" --target "${targets[@]}"

mkdir -p "${build}/fuzz-artifacts"
status=0
for target in "${targets[@]}"; do
  loader="${target#fuzz_}"
  # A working copy of the seeds, so new inputs do not land in the source tree.
  corpus="${build}/fuzz-corpus/${loader}"
  mkdir -p "${corpus}"
  cp -n "${root}/tests/fuzz/corpus/${loader}/"* "${corpus}/" 2>/dev/null || true
  echo "== ${target}: ${seconds} s"
  # -rss_limit_mb keeps a runaway allocation a finding instead of an OOM kill.
  if ! "${build}/tests/fuzz/${target}" -max_total_time="${seconds}" -rss_limit_mb=1024 -max_len=8192 \
      -artifact_prefix="${build}/fuzz-artifacts/${target}-" -print_final_stats=1 "${corpus}" 2>"${build}/fuzz-artifacts/${target}.log"; then
    echo "!! ${target} failed; see ${build}/fuzz-artifacts/${target}.log"
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb|cov:" "${build}/fuzz-artifacts/${target}.log" | tail -3 || true
done
exit "${status}"
