#!/usr/bin/env bash
# A real run recorded by fahr_logger and read back by an independent reader
# (check_mcap.mjs on Foxglove's npm packages, installed with `npm ci` from the
# committed package-lock.json into the build tree): every chunk, data and
# summary CRC, every message decoded with the file's own omgidl schemas, and
# per writer recorded + gaps + drops + skipped = sent, with sent equal to the
# writer's own count from its last ServiceStatus. The normal and loss runs
# also check fahr_trace's JSON (tick tracks, flows, counters) and render
# fahr_report's page in headless Chromium to a PNG (no script error, six
# plots of at least 100 points; FAHR_KEEP_REPORT=DIR keeps page and PNG).
#
#   record_run_test.sh BUILD_DIR install
#   record_run_test.sh BUILD_DIR VENDOR SECONDS [normal|loss|kill|replay]
#
# install: `npm ci` of the reader's packages into BUILD_DIR/tests/logger/js
# (outside any namespace: it needs the npm registry); CTest runs it first.
# normal: deployment/run_local.sh --record, nothing injected.
# loss:   an nftables rule drops 3 % of UDP datagrams (Cyclone: every
#         participant's traffic) and the recorder's queue is 64 KiB with a
#         slowed writer, so both gaps and recorder drops happen; the books
#         must still close exactly.
# kill:   fahr_logger with the gateway alone, SIGKILLed SECONDS after its
#         first chunk reached the disk; then
#         fahr_mcap recover rebuilds the .part, which must hold every
#         DevicePose older than one chunk plus 1 s at the kill.
# replay: a lockstep run of SECONDS of simulated time recorded (and read
#         back), then run again with fahr_replay feeding the recorded
#         DevicePoses in place of the gateway: the haptic and FEM output
#         hashes (and the poses') must equal the recorded run's.
# Runs inside a loopback-only network namespace (tests/run_in_netns.sh).
# Exit 77 (skipped) only if node or npm is absent.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "SKIPPED: node and npm are needed for the independent MCAP reader (tools/setup.sh installs them)"
  exit 77
fi

# The reader's packages, exactly as locked; reinstalled only when the lock changes.
js="$build/tests/logger/js"
if [ "$2" = install ]; then
  . "$repo/tests/support/npm_ci_locked.sh"
  npm_ci_locked "$repo/tests/logger/js" "$js"
  echo "record_run_test: reader packages installed in $js"
  exit 0
fi
vendor=$2
seconds=$3
mode=${4:-normal}
if [ ! -d "$js/node_modules/@mcap/core" ]; then
  echo "record_run_test: the reader's packages are not installed: run $0 $build install" >&2
  exit 1
fi
cp "$repo/tests/logger/js/check_mcap.mjs" "$js/"

out=$(mktemp -d /tmp/fahr-record-test-XXXXXX)
trap 'rm -rf "$out"' EXIT
export FAHR_RUN_LOCAL_IN_NETNS=1  # already in a namespace: run_local must not re-enter one
export FAHR_RUN_LOG_DIR="$out/logs"

check() {
  local file=$1
  node "$js/check_mcap.mjs" "$file" >"$out/check.json" || {
    echo "record_run_test: the independent reader found problems:" >&2
    node -e 'const d=require(process.argv[1]); console.error(d.problems.slice(0,20).join("\n")); console.error(JSON.stringify(d.accounting, null, 1))' "$out/check.json"
    return 1
  }
  node -e '
    const d = require(process.argv[1]);
    console.log(`record_run_test: ${d.messages} messages decoded, ${d.chunk_crcs} chunk CRCs + data and summary CRCs valid, ${d.schemas.length} schemas`);
    for (const r of d.accounting)
      console.log(`  ${r.topic.padEnd(24)} writer ${String(r.writer_id).padStart(10)} sent ${String(r.sent).padStart(6)} (writer says ${r.reported}) = recorded ${r.recorded} + gaps ${r.gaps} (before match ${r.leading_gaps}) + drops ${r.drops} + skipped ${r.skipped}`);
    console.log("  types decoded: " + Object.keys(d.samples).join(", "));' "$out/check.json"
}

case "$mode" in
  normal|loss)
    extra=()
    if [ "$mode" = loss ]; then
      nft add table inet fahr_loss
      # On input: a datagram dropped on output fails the sender's sendto
      # (EPERM), which is not what a lossy network does.
      nft add chain inet fahr_loss in '{ type filter hook input priority 0; }'
      nft add rule inet fahr_loss in meta l4proto udp numgen random mod 100 '<' 3 drop
      extra=(--record-arg --queue-mib --record-arg 1 --record-arg --writer-delay-us --record-arg 300)
    fi
    bash "$repo/deployment/run_local.sh" "$build" --dds "$vendor" --duration-s "$seconds" \
      --record "$out/run.mcap" "${extra[@]}" >"$out/run.log" 2>&1 || {
      echo "record_run_test: run_local failed:" >&2; tail -n 40 "$out/run.log" >&2; exit 1; }
    grep -A16 "^run_local: recording" "$out/run.log" || true
    check "$out/run.mcap"
    # The trace of the same file: valid JSON that Perfetto reads, a track
    # of tick slices per service, and pose -> tick -> command -> servo flows.
    "$build/tools/trace/fahr_trace" "$out/run.mcap" -o "$out/trace.json" | head -n 5
    node -e '
      const d = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
      const ev = d.traceEvents, count = {};
      for (const e of ev) count[e.ph] = (count[e.ph] ?? 0) + 1;
      const tickPids = new Set(ev.filter((e) => e.ph === "X" && e.name === "tick").map((e) => e.pid));
      const names = ev.filter((e) => e.ph === "M" && e.name === "process_name").map((e) => e.args.name);
      console.log(`record_run_test: trace.json: ${ev.length} events ${JSON.stringify(count)}, tick tracks: ${names.join(", ")}`);
      const ok = tickPids.size >= 3 && count.s > 0 && count.f > 0 && count.C > 0;
      if (!ok) console.error("record_run_test: the trace lacks tick tracks, flows or counters");
      process.exitCode = ok ? 0 : 1;' "$out/trace.json"
    # The report of the same file, rendered by headless Chromium to a PNG:
    # no script error, every plot drawn with at least 100 points.
    "$build/tools/report/fahr_report" "$out/run.mcap" -o "$out/report.html"
    if command -v chromium >/dev/null 2>&1; then
      chrome=(chromium --headless --no-sandbox --disable-gpu --hide-scrollbars)
      "${chrome[@]}" --window-size=1150,2800 --screenshot="$out/report.png" "file://$out/report.html" \
        >/dev/null 2>&1 || true
      check_div=$("${chrome[@]}" --dump-dom "file://$out/report.html" 2>/dev/null | grep -o '<div id="fahr-check"[^>]*>' || true)
      echo "record_run_test: report rendered: $check_div, PNG $(stat -c %s "$out/report.png" 2>/dev/null || echo 0) bytes"
      node -e '
        const m = /data-errors="(\d+)" data-plots="(\d+)" data-min-points="(\d+)"/.exec(process.argv[1] || "");
        const ok = m && m[1] === "0" && Number(m[2]) === 6 && Number(m[3]) >= 100;
        if (!ok) console.error("record_run_test: the report has script errors or a plot with fewer than 100 points");
        process.exitCode = ok ? 0 : 1;' "$check_div"
      [ -s "$out/report.png" ] || { echo "record_run_test: no PNG from headless Chromium" >&2; exit 1; }
      if [ -n "${FAHR_KEEP_REPORT:-}" ]; then cp "$out/report.png" "$out/report.html" "$FAHR_KEEP_REPORT/"; fi
    else
      echo "record_run_test: SKIPPED the report's rendering: chromium is not installed (tools/setup.sh installs it)"
    fi
    if [ "$mode" = loss ]; then
      # The injection must have shown: transport gaps and recorder drops.
      node -e '
        const d = require(process.argv[1]);
        const gaps = d.accounting.reduce((s, r) => s + r.gaps - r.leading_gaps, 0);
        const drops = d.accounting.reduce((s, r) => s + r.drops, 0);
        console.log(`record_run_test: injected loss seen: ${gaps} gaps after matching, ${drops} recorder drops`);
        process.exitCode = gaps > 0 && drops > 0 ? 0 : 1;' "$out/check.json"
    fi
    ;;
  kill)
    "$build/services/logger/fahr_logger" -o "$out/killed.mcap" --dds "$vendor" --domain 43 \
      >"$out/logger.log" 2>&1 &
    logger=$!
    for _ in $(seq 100); do grep -q "recording to" "$out/logger.log" && break; sleep 0.1; done
    "$build/services/device_gateway/fahr_device_gateway" --dds "$vendor" --domain 43 \
      --backend simulated --script intubation --duration-s $((seconds + 5)) >"$out/gateway.log" 2>&1 &
    gateway=$!
    # SECONDS of recording count from the first chunk on disk (a starved
    # machine may take seconds to start the gateway and match it).
    part_size() { stat -c %s "$out/killed.mcap.part" 2>/dev/null || echo 0; }
    empty=$(part_size)
    for _ in $(seq 600); do
      [ "$(part_size)" -gt "$empty" ] && break
      sleep 0.1
    done
    [ "$(part_size)" -gt "$empty" ] || {
      echo "record_run_test: the recorder wrote nothing within 60 s" >&2; cat "$out/logger.log" >&2; exit 1; }
    sleep "$seconds"
    kill_ns=$(date +%s%N)
    kill -KILL "$logger"
    wait "$logger" 2>/dev/null || true
    kill -INT "$gateway"; wait "$gateway" 2>/dev/null || true
    [ -f "$out/killed.mcap.part" ] || { echo "record_run_test: no .part left behind" >&2; exit 1; }
    "$build/tools/mcap/fahr_mcap" info "$out/killed.mcap.part" >/dev/null && {
      echo "record_run_test: a .part of a killed recorder reads as valid?" >&2; exit 1; }
    "$build/tools/mcap/fahr_mcap" recover "$out/killed.mcap.part"
    "$build/tools/mcap/fahr_mcap" info "$out/killed.mcap" | grep -E "^(messages|crc|valid)"
    # Every DevicePose logged before kill - 1 s - one chunk's span is in the
    # file: at 1 kHz with chunks closed by age (1 s), that is all poses up to
    # kill - 2 s.
    (cd "$js" && node --input-type=module -e '
      import { readFileSync } from "node:fs";
      import { McapIndexedReader } from "@mcap/core";
      import { loadDecompressHandlers } from "@mcap/support";
      const bytes = readFileSync(process.argv[1]);
      const killNs = BigInt(process.argv[2]);
      const readable = { size: async () => BigInt(bytes.length), read: async (o, s) => bytes.subarray(Number(o), Number(o + s)) };
      const r = await McapIndexedReader.Initialize({ readable, decompressHandlers: await loadDecompressHandlers() });
      let last = 0n, n = 0, first = 0n;
      for await (const m of r.readMessages({ topics: ["fahr/DevicePose"], validateCrcs: true })) {
        if (n === 0) first = m.logTime;
        n++; last = m.logTime;
      }
      const behind = Number(killNs - last) / 1e9;
      console.log(`record_run_test: recovered ${n} DevicePoses, the newest ${behind.toFixed(2)} s before the kill`);
      process.exitCode = n > 0 && behind <= 2.0 ? 0 : 1;' "$out/killed.mcap" "$kill_ns")
    ;;
  replay)
    # DevicePose is best effort: on a loaded machine the transport may lose
    # one (the books above count it as a gap), and a recording without it
    # cannot be replayed. That is the recording's loss, not the replay's
    # fault: such a recording is made again, at most three times in all.
    for attempt in 1 2 3; do
      rm -f "$out/lockstep.mcap"
      bash "$repo/deployment/run_local.sh" "$build" --dds "$vendor" --mode lockstep \
        --duration-s "$seconds" --record "$out/lockstep.mcap" >"$out/recorded.log" 2>&1 || {
        echo "record_run_test: the recorded lockstep run failed:" >&2; tail -n 40 "$out/recorded.log" >&2; exit 1; }
      check "$out/lockstep.mcap" | tee "$out/books.txt"
      grep -Eq "fahr/DevicePose .* gaps [1-9]" "$out/books.txt" || break
      echo "record_run_test: recording $attempt lost a DevicePose in transport; recording again"
      [ "$attempt" = 3 ] && { echo "record_run_test: three recordings each lost a DevicePose" >&2; exit 1; }
    done
    FAHR_RUN_LOG_DIR="$out/logs-replay" bash "$repo/deployment/run_local.sh" "$build" --dds "$vendor" \
      --mode lockstep --duration-s "$seconds" --replay "$out/lockstep.mcap" >"$out/replayed.log" 2>&1 || {
      echo "record_run_test: the replayed lockstep run failed:" >&2; tail -n 40 "$out/replayed.log" >&2; exit 1; }
    grep "^lockstep_clock: hash" "$out/recorded.log" | sed 's/^/  recorded: /'
    grep "^lockstep_clock: hash" "$out/replayed.log" | sed 's/^/  replayed: /'
    recorded=$(grep "^lockstep_clock: hash" "$out/recorded.log")
    replayed=$(grep "^lockstep_clock: hash" "$out/replayed.log")
    [ "$(echo "$recorded" | wc -l)" = 3 ] && [ "$recorded" = "$replayed" ] || {
      echo "record_run_test: the replayed run's hashes differ from the recorded run's" >&2; exit 1; }
    ;;
  *) echo "record_run_test: mode must be normal, loss, kill or replay" >&2; exit 2 ;;
esac
echo "record_run_test: passed ($mode, $vendor)"
