#!/usr/bin/env bash
# Sets up the machine, builds fahr and runs the main demo:
#   bash tools/run_demo.sh
# Until the end-to-end intubation demo exists (gateway, haptic and FEM
# services), the demo is the transport's: two processes exchange samples
# through fahr's transport and through each vendor's raw API, on Fast DDS,
# Cyclone DDS and across vendors, and the round-trip times are printed.
# As root it runs inside a loopback-only network namespace; otherwise it
# keeps both vendors on loopback through the profiles in deployment/dds.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${FAHR_BUILD_DIR:-$root/build}"

bash "$root/tools/setup.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j2 --target fahr_transport_latency

demo=("$build/tools/transport_latency/fahr_transport_latency" --round-trips 2000 --large-round-trips 100
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
