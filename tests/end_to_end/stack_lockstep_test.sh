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
# on Cyclone DDS against the same in one process. Last, two deformable
# bodies: the tongue and a copy of it 1 mm above (both under the blade), which
# one FEM service steps and the haptic service queries as one tissue, each
# with its own ContactSets and DeformationStates: Cyclone DDS against the same
# in one process, both bodies touched and moved, no set refused, and a larger
# peak force than the tongue's alone (the copy's reaction is felt).
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

# The in-process run of SCENE (its output in $tmp/NAME.txt) must give the
# hashes of the last Cyclone DDS run.
same_in_process() {
  local scene=$1 name=$2 what=$3
  "$build/sim/stack_sim_run/fahr_stack_sim_run" --seconds 4 --scene "$scene" | tee "$tmp/$name.txt"
  grep "^lockstep_clock: hash" "$tmp/$name.txt" | sort >"$tmp/$name.hashes"
  if ! diff "$tmp/cyclonedds.hashes" "$tmp/$name.hashes"; then
    echo "FAIL: $what the in-process run differs from the DDS run"
    exit 1
  fi
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
    -e "s/^  max_candidate_contacts: 96/  max_candidate_contacts: 96\n  compliance_columns: normals/" \
    "$repo/deployment/scenes/neonatal_intubation.yaml" >"$tmp/normals.yaml"
grep -q "^  compliance_columns: normals" "$tmp/normals.yaml" || { echo "FAIL: could not write the normals scene"; exit 1; }
cp "$tmp/cyclonedds.hashes" "$tmp/blocks.hashes"
run cyclonedds 63 "$tmp/normals.yaml"
same_in_process "$tmp/normals.yaml" normals_inprocess "with W along the normals"
# The option changed the physics (the FEM's W and the rows): not the same run.
if diff -q "$tmp/blocks.hashes" "$tmp/cyclonedds.hashes" >/dev/null; then
  echo "FAIL: W along the normals gave the same hashes as the 3x3 blocks"
  exit 1
fi

# Two deformable bodies: the tongue and a copy 1 mm above it.
bash "$repo/bench/support/two_tongues_scene.sh" "$repo/deployment/scenes/neonatal_intubation.yaml" \
  >"$tmp/two_bodies.yaml"
run cyclonedds 64 "$tmp/two_bodies.yaml"
same_in_process "$tmp/two_bodies.yaml" two_inprocess "with two deformable bodies"
for body in tongue tongue_b; do
  line=$(grep "^stack_sim: body '$body':" "$tmp/two_inprocess.txt") || { echo "FAIL: no line for body $body"; exit 1; }
  touched=$(sed -n 's/.*ticks with tool contacts \([0-9]*\),.*/\1/p' <<<"$line")
  moved=$(sed -n 's/.*largest node motion \([0-9.]*\) mm.*/\1/p' <<<"$line")
  refused=$(sed -n 's/.*refused: layout \([0-9]*\), unknown sphere \([0-9]*\);.*/\1 \2/p' <<<"$line")
  [ "${touched:-0}" -gt 100 ] || { echo "FAIL: the blade touched $body in ${touched:-0} ticks"; exit 1; }
  awk -v m="$moved" 'BEGIN { exit !(m > 1.0) }' || { echo "FAIL: $body moved only $moved mm"; exit 1; }
  [ "$refused" = "0 0" ] || { echo "FAIL: $body refused ContactSets ($refused)"; exit 1; }
done
# The peak force on the tongue alone and with both bodies, each in one
# process (the same measure; a DDS service's own summary line is lost when
# it has to be killed at the end of its run).
"$build/sim/stack_sim_run/fahr_stack_sim_run" --seconds 4 \
  --scene "$repo/deployment/scenes/neonatal_intubation.yaml" >"$tmp/one_inprocess.txt"
one=$(sed -n 's/^stack_sim: .* peak |F| \([0-9.]*\) N.*/\1/p' "$tmp/one_inprocess.txt")
two=$(sed -n 's/^stack_sim: .* peak |F| \([0-9.]*\) N.*/\1/p' "$tmp/two_inprocess.txt")
echo "peak |F|: tongue alone ${one:-?} N, tongue and its copy ${two:-?} N"
awk -v a="${one:-0}" -v b="${two:-0}" 'BEGIN { exit !(a > 0 && b > 1.2 * a) }' ||
  { echo "FAIL: two bodies under the blade gave no larger force (${two:-?} N) than one (${one:-?} N)"; exit 1; }
echo "PASS: identical hashes on both vendors and the pinned in-process ones, with W as blocks and along the normals, and with two deformable bodies"
