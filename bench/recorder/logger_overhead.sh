#!/usr/bin/env bash
# The haptic tick's thread-CPU time with and without fahr_logger, in one
# run: deployment/run_local.sh runs the demo for SECONDS; a listener
# collects the haptic service's tick spans (ServiceEvents) for the whole
# run and runs fahr_logger in every other 5 s window, then compares the
# ticks of both kinds of window.
#
#   bench/recorder/logger_overhead.sh [BUILD_DIR] [SECONDS] [VENDOR] [--markdown]
#
# FAHR_OVERHEAD_PIN=1: the haptic service on CPU 0, the logger on CPU 1
# (the FEM and gateway unpinned).
# As root it runs inside a loopback-only network namespace.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
seconds=${2:-60}
vendor=${3:-cyclonedds}
markdown=()
[ "${4:-}" = --markdown ] && markdown=(--markdown)
if [ "$(id -u)" -eq 0 ] && [ -z "${FAHR_RUN_LOCAL_IN_NETNS:-}" ]; then
  FAHR_RUN_LOCAL_IN_NETNS=1 exec "$repo/tests/run_in_netns.sh" bash "$0" "$build" "$seconds" "$vendor" "${markdown[@]}"
fi
logs=$(mktemp -d /tmp/fahr-overhead-XXXXXX)
pin_run=()
pin_logger=()
if [ "${FAHR_OVERHEAD_PIN:-0}" = 1 ]; then
  pin_run=(--cpus-haptic 0)
  pin_logger=(--logger-cpu 1)
fi
FAHR_RUN_LOG_DIR="$logs" bash "$repo/deployment/run_local.sh" "$build" --dds "$vendor" \
  --duration-s "$seconds" "${pin_run[@]}" >"$logs/run.log" 2>&1 &
run=$!
# The gateway starts once the services are ready: listen from then on.
for _ in $(seq 1200); do
  grep -q "^fahr_device_gateway: " "$logs/gateway.log" 2>/dev/null && break
  sleep 0.1
done
listen=$(awk "BEGIN { print $seconds - 2 }")
"$build/bench/recorder/fahr_bench_recorder" --overhead-s "$listen" --logger "$build/services/logger/fahr_logger" \
  --vendor "$vendor" --domain 42 --dir "$logs" "${pin_logger[@]}" "${markdown[@]}"
wait "$run" || { echo "logger_overhead: run_local failed" >&2; tail -n 20 "$logs/run.log" >&2; exit 1; }
rm -rf "$logs"
