#!/usr/bin/env bash
# The shipped neonatal scene's lockstep output hashes, pinned: fahr_stack_sim_run (gateway
# with the simulated hand's intubation script, haptic service, FEM service, in one process)
# for 4 s of simulated time must print these three hashes bit for bit. Any change to the
# floating-point order of the loop changes them; so does another BLAS kernel or compiler.
#   pinned_hashes_test.sh STACK_SIM_RUN SCENE
set -euo pipefail
run="${1:?usage: pinned_hashes_test.sh STACK_SIM_RUN SCENE}"
scene="${2:?usage: pinned_hashes_test.sh STACK_SIM_RUN SCENE}"

# Pinned on: an AMD EPYC (an Intel Xeon with AVX-512 gave the same earlier ones), OpenBLAS 0.3.21 (Debian libopenblas0-pthread) held to its
# Haswell kernels and one thread, g++ 12.2 (Debian 12), CMAKE_BUILD_TYPE=Release.
# The pinned hashes live beside this script; the DDS lockstep test compares its runs to them too.
pinned="$(dirname "$0")/neonatal_4s.hashes"
expected=$(cat "$pinned")

# The kernel OpenBLAS picks by itself depends on the CPU (AVX-512 on this one): pinning it makes
# CHOLMOD's rounding that of the machine the hashes were recorded on. One BLAS thread: the
# supernodal factorisation rounds differently with more.
export OPENBLAS_CORETYPE=Haswell OPENBLAS_NUM_THREADS=1
out=$(mktemp /tmp/fahr-pinned-hashes-XXXXXX)
trap 'rm -f "$out"' EXIT
command=("$run" --seconds 4 --scene "$scene")
status=0
"${command[@]}" >"$out" 2>&1 || status=$?
if [ "$status" -ne 0 ]; then
  cat "$out"
  echo "FAIL: ${command[*]} exited with $status"
  exit 1
fi
actual=$(grep '^lockstep_clock: hash' "$out" | sort -u)
if [ "$actual" != "$expected" ]; then
  cat "$out"
  echo "FAIL: the lockstep hashes of the neonatal scene (4 s) differ from the pinned ones"
  diff <(echo "$expected") <(echo "$actual") || true
  cat <<MSG
What changes them: the floating-point order of any step of the loop (the FEM's assembly and
solve, the contact solver, the device model, their summation order), the scene or the hand's
script, the BLAS kernel (OPENBLAS_CORETYPE, the OpenBLAS version, its thread count), the
compiler, its version or its flags (build type, -march, -ffast-math), the CPU's kernels.
A refactor must keep them. When a change is meant to alter the numbers, say so in its commit
and pin the new values: run
  OPENBLAS_CORETYPE=Haswell OPENBLAS_NUM_THREADS=1 ${command[*]}
and copy its three "lockstep_clock: hash" lines into $pinned
(on the machine and build named above it).
MSG
  exit 1
fi
echo "PASS: the neonatal scene's lockstep hashes (4 s) are the pinned ones"
