#!/usr/bin/env bash
# The whole stack in lockstep: device gateway (simulated hand, intubation
# script), FEM service and haptic service as separate processes under
# fahr_lockstep_clock, 4 s of simulated time (the blade enters the mouth and
# touches the tongue), run on Fast DDS and on Cyclone DDS. Every service's
# output hash must be the same on both: the runs are identical bit for bit,
# whatever the vendor and the load, so lockstep runs are reproducible. They
# must be the pinned hashes of the same run in one process
# (tests/determinism: fahr_stack_sim_run, the services' step code without
# transport), which stack_sim_pinned_hashes checks. Then once more with W
# along the normals (solver.compliance_columns: normals, 64 spheres, whose
# columns and normals cross DDS in DeformationState.compliance_normals),
# on Cyclone DDS against the same in one process.
#
# One BLAS thread everywhere: CHOLMOD's supernodal factorisation rounds
# differently with another OpenBLAS thread count (measured: the FEM hash
# changes, the gateway's and the haptic service's do not within 4 s).
#   stack_lockstep_test.sh BUILD_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build="${1:?usage: stack_lockstep_test.sh BUILD_DIR}"
# The BLAS kernel and threads the pinned hashes were recorded with.
export OPENBLAS_CORETYPE=Haswell OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
tmp=$(mktemp -d /tmp/fahr-stack-lockstep-XXXXXX)
trap 'rm -rf "$tmp"' EXIT

run() {
  local vendor=$1 domain=$2 scene=${3:-$repo/deployment/scenes/neonatal_intubation.yaml}
  local status=0
  FAHR_NETNS_TIMEOUT=170 FAHR_RUN_LOCAL_IN_NETNS=1 \
    "$repo/tests/run_in_netns.sh" bash "$repo/deployment/run_local.sh" "$build" --mode lockstep \
    --dds "$vendor" --domain "$domain" --duration-s 4 --scene "$scene" >"$tmp/$vendor.txt" 2>&1 || status=$?
  cat "$tmp/$vendor.txt"
  if [ "$status" -ne 0 ]; then
    echo "FAIL: the $vendor lockstep run exited with $status"
    exit 1
  fi
  grep -q "^lockstep_clock: completed after 4000 of 4000 steps" "$tmp/$vendor.txt" || { echo "FAIL: $vendor run incomplete"; exit 1; }
  grep "^lockstep_clock: hash" "$tmp/$vendor.txt" | sort >"$tmp/$vendor.hashes"
  [ "$(wc -l <"$tmp/$vendor.hashes")" -eq 3 ] || { echo "FAIL: $vendor run: expected 3 hashes"; exit 1; }
}

run cyclonedds 61
run fastdds 62
if ! diff "$tmp/cyclonedds.hashes" "$tmp/fastdds.hashes"; then
  echo "FAIL: the two vendors' lockstep runs differ"
  exit 1
fi
if ! diff "$tmp/cyclonedds.hashes" "$repo/tests/determinism/neonatal_4s.hashes"; then
  echo "FAIL: the DDS runs differ from the pinned in-process hashes (tests/determinism)"
  exit 1
fi
# The haptic service answered with contact: the blade reached the tongue.
grep -q "peak |F| 0.00" "$tmp/cyclonedds.txt" && { echo "FAIL: no contact force in 4 s of the script"; exit 1; }

# W along the normals: the shipped scene with two solver keys changed (mesh
# paths made absolute, the copy living in $tmp).
sed -e "s|\.\./\.\./meshes/|$repo/meshes/|" \
    -e "s/^  max_candidate_contacts: 80/  max_candidate_contacts: 80\n  compliance_columns: normals/" \
    "$repo/deployment/scenes/neonatal_intubation.yaml" >"$tmp/normals.yaml"
grep -q "^  compliance_columns: normals" "$tmp/normals.yaml" || { echo "FAIL: could not write the normals scene"; exit 1; }
cp "$tmp/cyclonedds.hashes" "$tmp/blocks.hashes"
run cyclonedds 63 "$tmp/normals.yaml"
"$build/sim/stack_sim_run/fahr_stack_sim_run" --seconds 4 --scene "$tmp/normals.yaml" | tee "$tmp/normals_inprocess.txt"
grep "^lockstep_clock: hash" "$tmp/normals_inprocess.txt" | sort >"$tmp/normals_inprocess.hashes"
if ! diff "$tmp/cyclonedds.hashes" "$tmp/normals_inprocess.hashes"; then
  echo "FAIL: with W along the normals the in-process run differs from the DDS run"
  exit 1
fi
# The option changed the physics (the FEM's W and the rows): not the same run.
if diff -q "$tmp/blocks.hashes" "$tmp/cyclonedds.hashes" >/dev/null; then
  echo "FAIL: W along the normals gave the same hashes as the 3x3 blocks"
  exit 1
fi
echo "PASS: identical hashes on both vendors and the pinned in-process ones, with W as blocks and along the normals"
