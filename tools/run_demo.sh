#!/usr/bin/env bash
# Sets up the machine, builds fahr and runs the main demo:
#   bash tools/run_demo.sh
# The demo is the first end-to-end run (deployment/run_local.sh): the device
# gateway with the simulated hand on the scripted intubation, the FEM
# service and the haptic service as separate processes over DDS for 20 s,
# then a summary (rates, forces against the device's limit, lost track).
# FAHR_DEMO_SECONDS changes the length; FAHR_DEMO_TRANSPORT=1 adds the
# transport's round-trip benchmark afterwards (about a minute).
# The run is recorded (fahr_logger, MCAP; Foxglove and Lichtblick open it)
# to FAHR_DEMO_RECORD (default build/recordings/demo_<date>_<time>.mcap;
# FAHR_DEMO_RECORD=0 records nothing), keeping one ContactSet and one FEM
# state in ten (the rest counted as skipped) so the file stays near 0.5 MB
# per second of run instead of 2 MB; the path is printed at the end.
# As root it runs inside a loopback-only network namespace; otherwise it
# keeps both vendors on loopback through the profiles in deployment/dds.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${FAHR_BUILD_DIR:-$root/build}"

bash "$root/tools/setup.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j2 --target fahr_device_gateway fahr_fem_service fahr_haptic_service fahr_run_summary fahr_lockstep_clock fahr_logger fahr_mcap_tool

echo "fahr demo: simulated neonatal intubation, gateway + FEM + haptic over DDS"
record=("--record" "${FAHR_DEMO_RECORD:-$build/recordings/demo_$(date +%Y%m%d_%H%M%S).mcap}"
        --record-decimate fahr/DeformationState=10 --record-decimate fahr/ContactSet=10)
[ "${FAHR_DEMO_RECORD:-}" = 0 ] && record=()
bash "$root/deployment/run_local.sh" "$build" --duration-s "${FAHR_DEMO_SECONDS:-20}" "${record[@]}"
if [ ${#record[@]} -gt 0 ]; then
  echo "fahr demo: recording ${record[1]} (inspect: $build/tools/mcap/fahr_mcap info ${record[1]}; open it in Foxglove or Lichtblick)"
fi

if [ "${FAHR_DEMO_TRANSPORT:-0}" = 1 ]; then
  cmake --build "$build" -j2 --target fahr_transport_latency
  demo=("$build/bench/transport_latency/fahr_transport_latency" --round-trips 2000 --large-round-trips 100
        --sizes small,100k)
  echo "fahr transport demo: round trips between two processes (microseconds)"
  if [ "$(id -u)" -eq 0 ]; then
    "$root/tests/run_in_netns.sh" "${demo[@]}"
  else
    # The benchmark starts its own participants; both vendors read these.
    FASTRTPS_DEFAULT_PROFILES_FILE="$root/deployment/dds/fastdds_loopback.xml" \
    CYCLONEDDS_URI="file://$root/deployment/dds/cyclonedds_loopback.xml" \
      "${demo[@]}"
  fi
fi
