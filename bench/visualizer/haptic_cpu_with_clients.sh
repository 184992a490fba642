#!/usr/bin/env bash
# What fahr_visualizer's clients cost the haptic tick, in one real-time run:
# fahr_visualizer runs beside the demo (deployment/run_local.sh: gateway on
# the simulated hand's intubation script, FEM and haptic services) for the
# whole run; once the script has played (13 s; the blade then rests out of
# the mouth, so every window sees the same tick), in every other window of
# W seconds a Foxglove WebSocket client (tests/visualizer/js
# foxglove_check.mjs, subscribed to every channel) and the page in Debian's
# chromium (playwright-core, software WebGL) are connected. The haptic
# service's per-tick thread CPU comes from its ServiceEvents tick spans,
# written by the run's fahr_run_summary (--tick-spans) and split by the
# windows' wall-clock bounds: a window with clients begins a second after
# both are connected and ends before they are stopped; one without begins
# a second after the previous clients are gone.
#
#   bench/visualizer/haptic_cpu_with_clients.sh [BUILD_DIR] [--runs 2] [--seconds 70]
#       [--window-s 8] [--markdown [FILE]]
#
# --markdown: also write the output to FILE (a name ending in .md), by
# default bench/results/<machine>/visualizer-haptic-cpu.md, under the
# header every bench writes (fahr_bench_results). Needs the clients
# installed: tests/visualizer/visualizer_run_test.sh BUILD_DIR install.
# A table per run (each run is one run of the stack: both kinds of window
# in it). About (S + 25) s a run. Not measured here: the tick under contact (the script
# presses for a few seconds only, too short for windows of both kinds). As
# root it runs inside a loopback-only network namespace (tests/run_in_netns.sh).
set -euo pipefail
load_at_start=$(cut -d" " -f1-3 /proc/loadavg)  # for the results file, written at the end
repo=$(cd "$(dirname "$0")/../.." && pwd)
command=("$0" "$@")
build="$repo/build"
runs=2
seconds=70
window_s=8
script_s=14  # the intubation script's 13 s, and a second to settle
markdown=()
args=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --window-s) window_s="$2"; shift 2 ;;
    --markdown)
      if [ $# -gt 1 ] && [[ "$2" == *.md ]]; then markdown=(--markdown "$2"); shift 2
      else markdown=(--markdown); shift; fi ;;
    -h|--help) sed -n '2,26p' "$0"; exit 0 ;;
    -*) echo "haptic_cpu_with_clients: unknown flag '$1'" >&2; exit 2 ;;
    *) build=$(cd "$1" && pwd); shift ;;
  esac
done
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "haptic_cpu_with_clients: --runs '$runs' is not a positive whole number" >&2; exit 2; }
for n in "$seconds" "$window_s"; do
  [[ "$n" =~ ^[0-9]+$ ]] && [ "$n" -gt 2 ] || { echo "haptic_cpu_with_clients: '$n' is not a whole number above 2" >&2; exit 2; }
done
[ "$seconds" -ge $((script_s + 2 * window_s)) ] || {
  echo "haptic_cpu_with_clients: --seconds must leave two windows after the script's ${script_s} s" >&2; exit 2; }
if [ "$(id -u)" -eq 0 ] && [ -z "${FAHR_RUN_LOCAL_IN_NETNS:-}" ]; then
  FAHR_RUN_LOCAL_IN_NETNS=1 exec "$repo/tests/run_in_netns.sh" bash "$0" "${args[@]}"
fi
js="$build/tests/visualizer/js"
vis="$build/services/visualizer/fahr_visualizer"
results="$build/bench/support/fahr_bench_results"
[ -d "$js/node_modules/playwright-core" ] || {
  echo "haptic_cpu_with_clients: run tests/visualizer/visualizer_run_test.sh $build install first" >&2; exit 2; }
[ -x "$vis" ] || { echo "haptic_cpu_with_clients: build fahr_visualizer first" >&2; exit 2; }
if [ ${#markdown[@]} -gt 0 ] && [ ! -x "$results" ]; then
  echo "haptic_cpu_with_clients: $results is missing; build it: cmake --build $build --target fahr_bench_results" >&2
  exit 2
fi
cp "$repo/tests/visualizer/js/foxglove_check.mjs" "$js/"

top=$(mktemp -d /tmp/fahr-vis-cpu-XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$top"
}
trap cleanup EXIT
port=8765

# The page in chromium until SIGINT: says "page: connected" once it draws
# deformation frames, and at the end how many it drew since.
page_client() {
  cd "$js" && exec node --input-type=module -e '
    import { chromium } from "playwright-core";
    const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true, handleSIGINT: false,
      args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"] });
    const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
    await page.goto(process.argv[1], { waitUntil: "load" });
    const frames = () => page.evaluate(() => window.fahrStats.deformFrames);
    while ((await frames()) === 0) await page.waitForTimeout(100);
    const first = await frames();
    console.log("page: connected");
    process.on("SIGINT", async () => {
      console.log(`page: ${(await frames()) - first} deformation frames`);
      await browser.close();
      process.exit(0);
    });' "http://127.0.0.1:$port/"
}

# One run: the visualizer, the demo with the summary writing tick spans,
# the windows; then its table.
one_run() {
  local run=$1 work="$top/run$1"
  mkdir -p "$work"
  "$vis" --dds cyclonedds --domain 42 --port "$port" >"$work/visualizer.log" 2>&1 &
  local vis_pid=$!
  pids+=("$vis_pid")
  for _ in $(seq 100); do grep -q "^fahr_visualizer: .* on http" "$work/visualizer.log" && break; sleep 0.1; done
  FAHR_RUN_LOG_DIR="$work/logs" bash "$repo/deployment/run_local.sh" "$build" --dds cyclonedds --domain 42 \
    --duration-s "$seconds" --summary-arg --tick-spans --summary-arg "$work/spans.csv" >"$work/run.log" 2>&1 &
  local run_pid=$!
  pids+=("$run_pid")
  # The windows begin after the gateway's script (the gateway starts once
  # the services are set up).
  for _ in $(seq 1200); do
    grep -q "^fahr_device_gateway: " "$work/logs/gateway.log" 2>/dev/null && break
    sleep 0.1
  done
  grep -q "^fahr_device_gateway: " "$work/logs/gateway.log" 2>/dev/null || {
    echo "haptic_cpu_with_clients: the run's gateway never started:" >&2; cat "$work/run.log" >&2; exit 1; }
  local run_start_s
  run_start_s=$(date +%s)
  sleep "$script_s"
  # Windows: without clients, with, without, ... until the run's end.
  : >"$work/windows.txt"
  local i=0 from_ns to_ns page fox
  while [ $(($(date +%s) - run_start_s + window_s)) -le "$seconds" ]; do
    if [ $((i % 2)) -eq 1 ]; then
      # The window begins once both clients are connected (chromium takes a
      # few seconds to start on a loaded machine), and a second to settle.
      (page_client) >"$work/page$i.log" 2>&1 &
      page=$!
      node "$js/foxglove_check.mjs" "ws://127.0.0.1:$port" $((window_s + 120)) \
        DevicePose,ForceCommand,ContactSet,DeformationState,SceneDescription,ServiceStatus \
        >"$work/foxglove$i.log" 2>&1 &
      fox=$!
      local waited=0
      while ! grep -q "^page: connected" "$work/page$i.log" && [ "$waited" -lt 600 ]; do
        sleep 0.1
        waited=$((waited + 1))
      done
      echo "window $i: the page connected after $((waited / 10)) s" >>"$work/clients.log"
      sleep 1
      from_ns=$(date +%s%N)
      sleep "$window_s"
      to_ns=$(date +%s%N)
      kill -INT "$page" "$fox" 2>/dev/null || true
      wait "$page" "$fox" || true
      cat "$work/page$i.log" >>"$work/clients.log"
      echo "$from_ns $to_ns with" >>"$work/windows.txt"
    else
      # A second for the previous window's clients to be gone.
      from_ns=$(($(date +%s%N) + 1000000000))
      sleep "$window_s"
      echo "$from_ns $(date +%s%N) without" >>"$work/windows.txt"
    fi
    i=$((i + 1))
  done
  wait "$run_pid" || { echo "haptic_cpu_with_clients: the run failed:" >&2; tail -n 20 "$work/run.log" >&2; exit 1; }
  grep -h "window\|^page: [0-9]" "$work/clients.log" | sed "s/^/run $run: /" >&2
  kill -INT "$vis_pid"
  wait "$vis_pid" || true
  pids=()

  # The haptic ticks in each kind of window; percentiles as the other
  # benches take them (the value at index floor(q (n - 1)) of the sorted list).
  awk -F, -v windows="$work/windows.txt" -v dir="$work" '
    BEGIN { while ((getline line < windows) > 0) { split(line, w, " "); n++; lo[n] = w[1]; hi[n] = w[2]; kind[n] = w[3] } }
    $1 == "haptic" { for (k = 1; k <= n; k++) if ($3 >= lo[k] && $3 < hi[k]) { print $5 > (dir "/cpu_" kind[k]); print $4 > (dir "/wall_" kind[k]) } }
  ' "$work/spans.csv"
  pct() { sort -n "$1" | awk -v q="$2" '{ v[NR] = $1 } END { if (NR) printf "%.1f", v[int(q * (NR - 1)) + 1] / 1000 }'; }
  row() {
    local kind=$1 label=$2
    [ -s "$work/cpu_$kind" ] || { echo "| $run | $label | 0 | | | | | | |"; return; }
    local ticks rate
    ticks=$(wc -l <"$work/cpu_$kind")
    # Ticks a second over the windows' measured spans: the haptic service
    # ticks once per DevicePose, so a starved gateway or service shows here.
    rate=$(awk -v k="$kind" -v n="$ticks" '$3 == k { s += ($2 - $1) * 1e-9 } END { if (s > 0) printf "%.0f", n / s }' \
      "$work/windows.txt")
    echo "| $run | $label | $ticks | $rate | $(pct "$work/cpu_$kind" 0.5) | $(pct "$work/cpu_$kind" 0.99)" \
      "| $(pct "$work/cpu_$kind" 0.999) | $(pct "$work/cpu_$kind" 1) | $(pct "$work/wall_$kind" 0.999) |"
  }
  ratio() { awk -v a="$(pct "$work/cpu_with" "$1")" -v b="$(pct "$work/cpu_without" "$1")" 'BEGIN { if (b > 0) printf "%.2f", a / b }'; }
  local frames windows
  frames=$(grep -o "page: [0-9]* deformation" "$work/clients.log" | awk '{ s += $2; n++ } END { if (n) printf "%.0f", s / n }')
  windows=$(wc -l <"$work/windows.txt")
  row without "without clients" >>"$top/rows.md"
  row with "Foxglove client + page" >>"$top/rows.md"
  echo "- run $run: $windows windows; with clients / without, CPU p50 $(ratio 0.5), p99 $(ratio 0.99)," \
    "p99.9 $(ratio 0.999); the page drew ${frames:-0} deformation frames a window on average." >>"$top/ratios.md"
}

: >"$top/rows.md"
: >"$top/ratios.md"
for run in $(seq 1 "$runs"); do one_run "$run"; done
{
  echo "## Haptic tick with and without fahr_visualizer's clients ($runs real-time runs, cyclonedds)"
  echo
  echo "In each run fahr_visualizer ran for the whole ${seconds} s (the intubation script, then the blade"
  echo "at rest out of the mouth); after the script's first ${script_s} s a Foxglove WebSocket client (every"
  echo "channel) and the page in chromium were connected in every other ${window_s} s window (measured from"
  echo "a second after both were connected until they were stopped; without clients, from a second after"
  echo "the previous ones were gone). Ticks from the haptic service's ServiceEvents tick spans, on $(nproc) cores."
  echo
  echo "| run | phase | ticks | ticks/s | CPU p50 us | CPU p99 us | CPU p99.9 us | CPU max us | wall p99.9 us |"
  echo "|---:|---|---:|---:|---:|---:|---:|---:|---:|"
  cat "$top/rows.md"
  echo
  cat "$top/ratios.md"
} >"$top/out.md"
cat "$top/out.md"
if [ ${#markdown[@]} -gt 0 ]; then
  "$results" visualizer-haptic-cpu "${markdown[@]}" --started "$SECONDS" "$load_at_start" -- "${command[@]}" <"$top/out.md" >/dev/null
fi
