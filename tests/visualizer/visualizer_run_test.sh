#!/usr/bin/env bash
# fahr_visualizer against real runs, read by independent clients installed
# with `npm ci` from the committed package-lock.json (tests/visualizer/js):
#
#   visualizer_run_test.sh BUILD_DIR install
#   visualizer_run_test.sh BUILD_DIR foxglove|browser|replay|remote
#
# install:  npm ci of the clients into BUILD_DIR/tests/visualizer/js (outside
#           any namespace: it needs the npm registry); CTest runs it first.
# foxglove: a realtime run; a Foxglove WebSocket client (@foxglove/ws-protocol)
#           decodes DevicePose, ForceCommand, ContactSet, DeformationState,
#           SceneDescription and ServiceStatus with the advertised omgidl
#           schemas, and its client publishing is refused.
# browser:  a lockstep run of the intubation script paced to real time at
#           most (run_local.sh --pace 1, so the page sees it as it would
#           happen); Debian's chromium (playwright-core) opens the page
#           before the run starts: tongue vertices updating at the display
#           rate, force arrow, pixels in the tongue's bounds differing
#           between the rest frame and a pressed one, no console error.
# replay:   a lockstep run of the overshoot script on a 100 kPa tongue
#           (the shipped 10 kPa one yields and never reaches the device's
#           limit: bench/results/amd-epyc-2c/overshoot.md, overshoot-100kpa.md),
#           recorded by fahr_logger, replayed by the visualizer (indexed
#           seeks) in the page: paused in the hand's first second, the rest
#           frame against tests/visualizer/reference/rest_side.png within
#           the tolerance of js/image_compare.mjs, and two perturbed frames
#           (camera turned 3 mm, tongue colours 10 % off) outside it; played,
#           and paused again once the device has lost track: the grey device
#           blade's pixels change when its toggle hides it; a seek and a
#           pause exercised.
# remote:   the gateway on --backend remote and the visualizer with
#           --allow-remote-input: poses sent as the page's mouse device
#           reach the gateway (its DevicePose follows them, clamped).
# FAHR_KEEP_SCREENSHOTS=DIR keeps the PNGs (live_rest, lost_track,
# live_later, live_blade_view, replay_rest, replay_early, replay_later)
# and the JSON.
# FAHR_UPDATE_REFERENCE=1 (replay mode) writes the rest frame to
# tests/visualizer/reference/rest_side.png instead of comparing: after a
# change to the page's drawing or the scene, or on another chromium; look
# at the new PNG before committing it. Runs inside a loopback-only
# network namespace (tests/run_in_netns.sh). Exit 77 only if node, npm or
# chromium is absent.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "$1" && pwd)
mode=$2
for tool in node npm chromium; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIPPED: $tool is needed (tools/setup.sh installs it)"
    exit 77
  fi
done
js="$build/tests/visualizer/js"
if [ "$mode" = install ]; then
  . "$repo/tests/support/npm_ci_locked.sh"
  npm_ci_locked "$repo/tests/visualizer/js" "$js"
  echo "visualizer_run_test: clients installed in $js"
  exit 0
fi
[ -d "$js/node_modules/playwright-core" ] || { echo "visualizer_run_test: run $0 $build install first" >&2; exit 1; }
cp "$repo"/tests/visualizer/js/*.mjs "$js/"
vis="$build/services/visualizer/fahr_visualizer"
[ -f "$build/services/visualizer/web/app.js" ] || { echo "visualizer_run_test: the page is not built" >&2; exit 1; }

out=$(mktemp -d /tmp/fahr-visualizer-test-XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [ -n "${FAHR_KEEP_SCREENSHOTS:-}" ]; then
    mkdir -p "$FAHR_KEEP_SCREENSHOTS"
    cp "$out"/*.png "$out"/*.json "$FAHR_KEEP_SCREENSHOTS/" 2>/dev/null || true
    cp -r "$out/logs" "$FAHR_KEEP_SCREENSHOTS/" 2>/dev/null || true
  fi
  rm -rf "$out"
}
trap cleanup EXIT
export FAHR_RUN_LOCAL_IN_NETNS=1
export FAHR_RUN_LOG_DIR="$out/logs"
port=8765
url="http://127.0.0.1:$port/"

start_visualizer() {
  "$vis" --port "$port" "$@" >"$out/visualizer.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do grep -q "^fahr_visualizer: .* on http" "$out/visualizer.log" && return 0; sleep 0.1; done
  echo "visualizer_run_test: the visualizer did not start:" >&2; cat "$out/visualizer.log" >&2; exit 1
}
stop_visualizer() {
  kill -INT "${pids[0]}"; wait "${pids[0]}" || true
  pids=("${pids[@]:1}")
  tail -n 1 "$out/visualizer.log"
}
# A realtime run in the background: run_local.sh with SECONDS and SCRIPT.
start_run() {
  bash "$repo/deployment/run_local.sh" "$build" --dds cyclonedds --domain 42 --duration-s "$1" \
    --script "$2" >"$out/run.log" 2>&1 &
  pids+=($!)
}

case "$mode" in
  foxglove)
    start_visualizer --dds cyclonedds --domain 42
    start_run 20 intubation
    node "$js/foxglove_check.mjs" "ws://127.0.0.1:$port" 240 \
      DevicePose,ForceCommand,ContactSet,DeformationState,SceneDescription,ServiceStatus,GlotticView | tee "$out/foxglove.json"
    stop_visualizer
    ;;
  browser)
    start_visualizer --dds cyclonedds --domain 42
    # 7 s of the intubation script: the blade reaches the tongue about 3 s
    # in and presses from 5 s. The run starts once the page is open (the
    # check writes page_open), so the page sees the rest frame however
    # slowly the browser starts.
    node "$js/browser_check.mjs" "$url" "$out" 300 live >"$out/browser.json" &
    checker=$!
    pids+=("$checker")
    for _ in $(seq 1800); do
      [ -f "$out/page_open" ] || ! kill -0 "$checker" 2>/dev/null && break
      sleep 0.1
    done
    [ -f "$out/page_open" ] || echo "visualizer_run_test: the page did not open within 180 s" >&2
    bash "$repo/deployment/run_local.sh" "$build" --dds cyclonedds --domain 42 --mode lockstep \
      --pace 1 --script intubation --duration-s 7 >"$out/run.log" 2>&1 &
    pids+=($!)
    status=0
    wait "$checker" || status=$?
    cat "$out/browser.json"
    stop_visualizer
    [ "$status" -eq 0 ] || exit "$status"
    ;;
  replay)
    # The overshoot script: the hand presses at 4.5 s and pushes past the
    # limit from 5.5 s; the 100 kPa tongue holds, the device loses track.
    # Paced, so the recording's clock never runs behind simulated time and
    # the page can pause in the hand's first second.
    sed -e 's#youngs_modulus_pa: 10000$#youngs_modulus_pa: 100000#' -e "s#\.\./\.\./meshes/#$repo/meshes/#g" \
      "$repo/deployment/scenes/neonatal_intubation.yaml" >"$out/stiff_tongue.yaml"
    grep -q "youngs_modulus_pa: 100000" "$out/stiff_tongue.yaml" || { echo "visualizer_run_test: the scene's modulus line moved" >&2; exit 1; }
    bash "$repo/deployment/run_local.sh" "$build" --dds cyclonedds --domain 42 --mode lockstep \
      --script overshoot --scene "$out/stiff_tongue.yaml" --duration-s 7 --pace 1 --record "$out/run.mcap" \
      >"$out/run.log" 2>&1 || {
      echo "visualizer_run_test: the recorded run failed:" >&2; tail -n 30 "$out/run.log" >&2; exit 1; }
    # A lockstep recording holds every sample of the four streams from step
    # 0 (run_local.sh starts the clock once the recorder has every writer).
    awk '$1 ~ /^fahr\/(DevicePose|ForceCommand|ContactSet|DeformationState)$/ && NF == 8 && $3 != $4 { bad = 1; print "visualizer_run_test: the recording lacks samples: " $0 }
         END { exit bad }' "$out/run.log" >&2 || exit 1
    # 7 s recorded, played from its start at full speed after the rest
    # frame, watched until the device has lost track (about 5.3 s in).
    start_visualizer --replay "$out/run.mcap" --speed 1
    node "$js/browser_check.mjs" "$url" "$out" 10 replay "$repo/tests/visualizer/reference/rest_side.png" \
      | tee "$out/replay.json"
    # Seek to the middle and pause: the position must follow (as soon as
    # the server says so; 30 s for a starved machine).
    (cd "$js" && node --input-type=module -e '
      import WebSocket from "ws";
      const ws = new WebSocket(process.argv[1]);
      let last = null, sent = false;
      const held = (m) => m && m.paused && Math.abs(m.t - m.duration / 2) < 0.1;
      const end = (ok) => {
        console.log(`visualizer_run_test: after seek + pause: t ${last?.t} of ${last?.duration} s, paused ${last?.paused}`);
        process.exit(ok ? 0 : 1);
      };
      ws.on("message", (d, binary) => {
        if (binary) return;
        const m = JSON.parse(d.toString());
        if (m.op !== "replay") return;
        last = m;
        if (!sent) { sent = true; ws.send(JSON.stringify({ op: "replay", action: "seek", value: m.duration / 2 }));
                     ws.send(JSON.stringify({ op: "replay", action: "pause" })); }
        else if (held(m)) end(true);
      });
      setTimeout(() => end(held(last)), 30000);' "ws://127.0.0.1:$port/ws")
    stop_visualizer
    ;;
  remote)
    start_visualizer --dds cyclonedds --domain 44 --allow-remote-input
    "$build/services/device_gateway/fahr_device_gateway" --dds cyclonedds --domain 44 --backend remote \
      --duration-s 90 >"$out/gateway.log" 2>&1 &
    pids+=($!)
    (cd "$js" && node --input-type=module -e '
      import WebSocket from "ws";
      import wsProtocol from "@foxglove/ws-protocol";
      import { parseIDL } from "@foxglove/omgidl-parser";
      import { MessageReader } from "@foxglove/omgidl-serialization";
      const page = new WebSocket(process.argv[1] + "/ws");
      const fox = new wsProtocol.FoxgloveClient({ ws: new WebSocket(process.argv[1], [wsProtocol.FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
      let reader = null, last = null, sub = null;
      fox.on("advertise", (chs) => { for (const c of chs) if (c.topic === "fahr/DevicePose") { reader = new MessageReader(c.schemaName, parseIDL(c.schema)); sub = fox.subscribe(c.id); } });
      fox.on("message", ({ subscriptionId, data }) => { if (subscriptionId === sub) last = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength)); });
      const target = [0.02, -0.01, 0.5];  // z beyond the workspace: clamped
      page.on("open", () => setInterval(() => page.send(JSON.stringify({ op: "pose", p: target, q: [1, 0, 0, 0] })), 20));
      // Judged once the gateway follows (discovery on a starved machine can
      // take seconds), or as it stands after 60 s.
      const followed = (p) => p && Math.abs(p.z) < 0.5 && p.z !== 0;
      const end = () => {
        const p = last?.world_from_stylus?.position_m;
        console.log(`visualizer_run_test: mouse pose sent ${JSON.stringify(target)}, gateway DevicePose at ${p ? [p.x, p.y, p.z].map((v) => v.toFixed(4)).join(", ") : "none"}`);
        process.exit(followed(p) ? 0 : 1);
      };
      setInterval(() => { if (followed(last?.world_from_stylus?.position_m)) end(); }, 100);
      setTimeout(end, 60000);' "ws://127.0.0.1:$port")
    stop_visualizer
    grep -E "remote|backend" "$out/gateway.log" | head -n 3 || true
    ;;
  *) echo "visualizer_run_test: mode must be install, foxglove, browser, replay or remote" >&2; exit 2 ;;
esac
echo "visualizer_run_test: passed ($mode)"
