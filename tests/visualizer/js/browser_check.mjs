// Debian's chromium, driven headless by playwright-core (no browser
// download), against a fahr_visualizer with a run going: the page loads,
// the scene arrives, the tongue's vertices update at the display rate, the
// force arrow appears, the pixels inside the tongue's projected bounds differ
// between the rest frame and a later (pressed) one, and the console stays
// free of errors. Screenshots go to OUT_DIR.
//   node browser_check.mjs URL OUT_DIR SECONDS live|replay [REFERENCE.png]
//
// live: the page is opened before a (paced) lockstep run starts, so its
// first frame is the rest state.
// replay (a lockstep recording of the overshoot script): first the rest
// frame, held: played from its start and paused at the first ForceCommand
// (the hand holds its first pose for the first second of simulated time),
// the canvas on the "side" camera, halved, against REFERENCE.png
// (image_compare.mjs states the tolerance); a frame with the camera turned
// by a 2-pixel drag (about 3 mm) and one with the tongue's colours off by
// 10 % must both fail it. Then the recording plays on; once the device
// has lost track it is paused again, and the cells of a grid over the grey
// device blade's projected bounds must change when its toggle hides it,
// ten times more than when the held frame is drawn again.
// Both are measured on a held replay, not the live run: on two cores the
// software-rendered page draws a few frames a second beside the running
// stack, so a live capture lands anywhere in the hand's first second or
// after it, and the scene moves between two live captures.
// FAHR_UPDATE_REFERENCE=1 writes the rest frame to REFERENCE.png instead
// of comparing.
// Prints one JSON line; exit 0 if every check passed.
import { chromium } from "playwright-core";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { TOLERANCE, compareImages, decodePng, scaledInRect } from "./image_compare.mjs";

const [url, out, secondsText, mode = "live", referencePath] = process.argv.slice(2);
const seconds = Number(secondsText ?? 10);
// Both scripts hold the hand at its first pose for the first second of
// simulated time (libs/device trajectory.cpp): the blade and the tongue at
// rest.
const REST_END_S = 0.95;
// The intubation's first 7 s lean about 1 N on the tongue, which yields on
// its floor (0.99 N peak on the shipped scene); a blade that never touches
// it gives 0.
const PRESSED_N = 0.5;
const BACKGROUND = [0x1d, 0x20, 0x24]; // the page's clear colour
const updateReference = process.env.FAHR_UPDATE_REFERENCE === "1";
const problems = [];
const consoleErrors = [];
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
page.on("console", (m) => {
  if (m.type() === "error") consoleErrors.push(m.text());
});
page.on("pageerror", (e) => consoleErrors.push(String(e)));
await page.goto(url, { waitUntil: "load" });
// The page is open: a live run may start (visualizer_run_test.sh waits for
// this, so a browser slower to start than the services still sees the rest).
writeFileSync(join(out, "page_open"), "");

const stats = () => page.evaluate(() => JSON.parse(JSON.stringify(window.fahrStats)));
// Luminance of the canvas on a 48 x 48 grid over a rectangle (whole
// pixels inside the canvas: chromium draws nothing from a source rectangle
// that reaches past the canvas, even by a rounding error).
const grab = (rect) =>
  page.evaluate((r) => {
    const src = document.querySelector("#view canvas");
    const c = document.createElement("canvas");
    c.width = 48;
    c.height = 48;
    const g = c.getContext("2d");
    const x = Math.min(src.width - 1, Math.max(0, Math.floor(r.x)));
    const y = Math.min(src.height - 1, Math.max(0, Math.floor(r.y)));
    const w = Math.max(1, Math.min(src.width - x, Math.ceil(r.w)));
    const h = Math.max(1, Math.min(src.height - y, Math.ceil(r.h)));
    g.drawImage(src, x, y, w, h, 0, 0, 48, 48);
    const d = g.getImageData(0, 0, 48, 48).data;
    const lum = [];
    for (let i = 0; i < d.length; i += 4) lum.push(0.299 * d[i] + 0.587 * d[i + 1] + 0.114 * d[i + 2]);
    return lum;
  }, rect);
// The canvas as drawn two frames after the page has both a deformation and
// a state frame, halved, as PNG; with the simulated times of the newest
// frames (read after the draw, so the drawn ones are no newer).
const capture = () =>
  page.evaluate(async (timeoutMs) => {
    const st = window.fahrStats;
    const nextFrame = () => new Promise((resolve) => requestAnimationFrame(() => resolve()));
    const end = performance.now() + timeoutMs;
    while (!(st.deformFrames > 0 && st.stateFrames > 0) && performance.now() < end) await nextFrame();
    if (!(st.deformFrames > 0 && st.stateFrames > 0)) return null;
    await nextFrame();
    await nextFrame();
    const src = document.querySelector("#view canvas");
    const c = document.createElement("canvas");
    c.width = Math.round(src.width / 2);
    c.height = Math.round(src.height / 2);
    c.getContext("2d").drawImage(src, 0, 0, c.width, c.height);
    return {
      png: c.toDataURL("image/png").split(",")[1],
      stateSimTime: st.stateSimTime,
      deformSimTime: st.deformSimTime,
      tongueRect: st.tongueRect,
    };
  }, 300000);
const nextFrames = () =>
  page.evaluate(
    () => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(() => resolve()))),
  );
const pixelChange = (a, b) => {
  let d = 0;
  for (let i = 0; i < a.length; i++) d += Math.abs(a[i] - b[i]);
  return a.length ? d / a.length : 0;
};

// Waits return as soon as the page shows what they wait for; their bounds
// are for a page that never does, long enough for a starved machine (a
// page drawn in software beside a station, on two cores whose host steals
// them) to get there late.
async function waitFor(pred, timeoutMs, what) {
  const end = Date.now() + timeoutMs;
  while (Date.now() < end) {
    const s = await stats();
    if (pred(s)) return s;
    await page.waitForTimeout(100);
  }
  problems.push(`timed out waiting for ${what}`);
  return stats();
}

// The rest frame, held (the replay paused in the hand's first second), the
// reference comparison and the two perturbations that must fail it.
// Returns the rest frame's tongue luminance and the tongue's bounds.
async function checkRestFrame(result) {
  // The force arrow and the contact dots are left out of the comparison: in
  // the hand's first second the force is a few millinewtons either side of
  // the arrow's threshold, so whether it is drawn is not the renderer's
  // doing.
  await page.evaluate(() => {
    window.fahrShow("arrow", false);
    window.fahrShow("contacts", false);
  });
  const rest = await capture();
  if (!rest) {
    problems.push("no deformation and state frames to compare with the reference");
    return { lum: [], rect: null };
  }
  writeFileSync(join(out, "replay_rest.png"), Buffer.from(rest.png, "base64"));
  const restLum = { lum: await grab(rest.tongueRect), rect: rest.tongueRect };
  // The camera turned by a 2-pixel drag on the canvas: OrbitControls turns
  // it by 2 pi x 2 / 700 rad about the target 0.16 m away: 2.9 mm.
  const box = await page.locator("#view canvas").boundingBox();
  const cx = box.x + box.width / 2;
  const cy = box.y + box.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 2, cy, { steps: 2 });
  await page.mouse.up();
  const turned = await capture();
  await page.evaluate(() => window.fahrSetCamera("side"));
  const again = await capture();
  await page.evaluate(() => {
    window.fahrShow("arrow", true);
    window.fahrShow("contacts", true);
  });
  const times = [rest, turned, again].map((c) => Math.max(c.stateSimTime, c.deformSimTime));
  result.restSimTimes = times.map((t) => Number(t.toFixed(3)));
  if (times.some((t) => !(t < REST_END_S)))
    problems.push(`the rest frames show ${result.restSimTimes.join(", ")} s, not before ${REST_END_S} s`);
  const restImage = decodePng(Buffer.from(rest.png, "base64"));
  // The same held state drawn again: what the renderer alone changes.
  result.restRepeat = compareImages(decodePng(Buffer.from(again.png, "base64")), restImage);
  if (updateReference) {
    // Only a rest frame becomes the reference.
    if (times.some((t) => !(t < REST_END_S))) return restLum;
    writeFileSync(referencePath, Buffer.from(rest.png, "base64"));
    result.referenceWritten = referencePath;
    return restLum;
  }
  const reference = decodePng(readFileSync(referencePath));
  result.tolerance = TOLERANCE;
  result.restAgainstReference = compareImages(restImage, reference);
  result.turnedCameraAgainstReference = compareImages(decodePng(Buffer.from(turned.png, "base64")), reference);
  const r = rest.tongueRect;
  const half = { x: r.x / 2, y: r.y / 2, w: r.w / 2, h: r.h / 2 };
  result.tongueColoursOffAgainstReference = compareImages(scaledInRect(restImage, half, 0.9, BACKGROUND), reference);
  if (!result.restAgainstReference.within)
    problems.push(`the rest frame does not match ${referencePath}: ${JSON.stringify(result.restAgainstReference)}`);
  if (result.turnedCameraAgainstReference.within) problems.push("a camera turned by 2.9 mm still matches the reference");
  if (result.tongueColoursOffAgainstReference.within) problems.push("tongue colours 10 % off still match the reference");
  return restLum;
}

// Plays the replay from `from` s at `speed` until the page has a
// ForceCommand ("command") or draws the grey device blade ("ghost"), and
// pauses it from the page at once (a poll every 5 ms: a slower round trip
// through the test would let the replay run on).
async function playUntil(kind, speed, from) {
  await page.evaluate(() => window.fahrSend({ op: "replay", action: "pause" }));
  await page.evaluate((t) => window.fahrSend({ op: "replay", action: "seek", value: t }), from);
  // Frames already on their way from before the seek arrive first.
  await page.waitForTimeout(500);
  await page.evaluate(
    ({ kind, speed }) =>
      new Promise((resolve) => {
        const st = window.fahrStats;
        st.stateSimTime = -1;
        const reached = () => (kind === "ghost" ? st.ghostVisible : st.stateSimTime >= 0);
        window.fahrSend({ op: "replay", action: "speed", value: speed });
        window.fahrSend({ op: "replay", action: "play" });
        const end = performance.now() + 60000;
        const poll = setInterval(() => {
          if (!reached() && performance.now() < end) return;
          clearInterval(poll);
          window.fahrSend({ op: "replay", action: "pause" });
          resolve();
        }, 5);
      }),
    { kind, speed },
  );
  await waitFor((x) => x.replay?.paused, 30000, `the replay paused (${kind})`);
  await nextFrames();
}

// The grey device blade, measured on the paused replay: luminance inside
// its projected bounds in two frames with it drawn, then with it hidden
// (the page's toggle).
async function checkGhost(result) {
  const s = await stats();
  if (!s.ghostVisible || !s.ghostRect) {
    problems.push(`the replay paused at ${s.replay?.t} s with no grey device blade drawn`);
    return;
  }
  const rect = s.ghostRect;
  result.lostTrackAtS = s.stateSimTime;
  await page.screenshot({ path: join(out, "lost_track.png") });
  const drawn = await grab(rect);
  await nextFrames();
  const drawnAgain = await grab(rect);
  const toggle = page.locator("#toggles button", { hasText: "ghost" });
  await toggle.click();
  await waitFor((x) => !x.ghostVisible, 30000, "the grey device blade hidden by its toggle");
  await nextFrames();
  const hidden = await grab(rect);
  await page.screenshot({ path: join(out, "lost_track_hidden.png") });
  await toggle.click();
  // Cells of the 48 x 48 grid whose luminance moved by more than 4 (of
  // 255): the translucent grey blade over the dark background or the
  // tongue moves its cells by 10-40; the paused scene drawn twice moves none.
  const changedCells = (a, b) => a.filter((v, i) => Math.abs(v - b[i]) > 4).length;
  result.ghostRect = rect;
  result.ghostCellsChangedWhenHidden = changedCells(drawnAgain, hidden);
  result.ghostCellsChangedWhenRedrawn = changedCells(drawn, drawnAgain);
  result.ghostMeanChangeWhenHidden = Number(pixelChange(drawnAgain, hidden).toFixed(2));
  if (!(rect.w >= 4 && rect.h >= 4)) problems.push(`the grey device blade covers ${rect.w} x ${rect.h} pixels`);
  // At least 1 % of the grid (23 cells), and ten times what a redraw moves.
  if (
    !(
      result.ghostCellsChangedWhenHidden >= 23 &&
      result.ghostCellsChangedWhenHidden >= 10 * result.ghostCellsChangedWhenRedrawn
    )
  )
    problems.push(
      `the grey device blade hardly shows: ${result.ghostCellsChangedWhenHidden} cells change when it is hidden, ${result.ghostCellsChangedWhenRedrawn} when redrawn`,
    );
}

const result = { mode };
let s = await waitFor((x) => x.sceneFrames > 0, 300000, "the scene");
await page.evaluate(() => window.fahrSetCamera("side"));
// The rest frame's tongue luminance, the tongue's bounds then, and its
// vertex checksum: what the press must change.
let first = [];
let rect = null;
let firstChecksum = 0;
let ghostChecked = false;
if (mode === "live") {
  // The first frames of the run: the rest state (the blade reaches the
  // tongue about 3 s into the script).
  const rest = await capture();
  if (!rest) problems.push("no deformation and state frames within 300 s");
  result.firstSimTime = rest && Number(Math.max(rest.stateSimTime, rest.deformSimTime).toFixed(3));
  s = await stats();
  firstChecksum = s.positionsChecksum;
  rect = rest?.tongueRect ?? null;
  first = rect ? await grab(rect) : [];
  if (rest) writeFileSync(join(out, "live_rest.png"), Buffer.from(rest.png, "base64"));
} else {
  // The recording's clock is the paced lockstep run's wall clock: the
  // services' set-up first (no ForceCommand), then at most real time. At
  // 4x to its first ForceCommand; then back 3 s and at half speed to it
  // again, paused at once: well inside the hand's first second.
  await page.evaluate(() => window.fahrSend({ op: "replay", action: "pause" }));
  await waitFor((x) => x.replay?.paused, 30000, "the replay paused");
  // A page that draws slowly (software GL on two cores) pauses late, so the
  // rest frame is found by seeking the paused replay instead: a seek hands
  // the page the newest samples up to that moment, whatever its speed.
  // Bisect between a moment without a ForceCommand and one with, until the
  // hand's simulated time is inside its first second.
  // The paused replay sends state frames only when a seek changes the
  // store: wait for one after the seek, then until none has come for
  // 400 ms (the store is cleared, then refilled), however slowly the page
  // draws.
  const seekAndRead = async (t) => {
    const before = (await stats()).stateFrames;
    await page.evaluate((v) => window.fahrSend({ op: "replay", action: "seek", value: v }), t);
    await waitFor(
      (x) => Math.abs((x.replay?.t ?? -1) - t) < 0.02 && x.stateFrames > before,
      20000,
      `the seek to ${t} s`,
    );
    let seen = (await stats()).stateFrames;
    for (let i = 0; i < 50; i++) {
      // 400 ms and two drawn frames: a page that draws slowly reads its
      // socket slowly too.
      await page.waitForTimeout(400);
      await nextFrames();
      const now = (await stats()).stateFrames;
      if (now === seen) break;
      seen = now;
    }
    const sim = (await stats()).stateSimTime;
    result.restProbes.push([Number(t.toFixed(3)), sim]);
    return sim;
  };
  result.restProbes = [];
  let lo = 0;
  // (Not the very end: after the run's last samples a seek may change
  // nothing the page is sent.)
  let hi = 0.8 * ((await stats()).replay?.duration ?? 0);
  let sim = await seekAndRead(hi);
  // Up to 24 halvings: a recorder starved for a while receives the held-up
  // samples in one burst, a simulated second within a few milliseconds of
  // its clock (0.95 s of the script within 23 ms in one run here), and the
  // bisection must reach inside it.
  for (let probe = 0; probe < 24 && !(sim >= 0 && sim < 0.5 * REST_END_S); probe++) {
    const mid = (lo + hi) / 2;
    sim = await seekAndRead(mid);
    if (sim < 0) lo = mid;
    else hi = mid;
  }
  if (!(sim >= 0 && sim < REST_END_S)) sim = await seekAndRead(hi);
  await nextFrames();
  result.restPausedAtS = (await stats()).replay?.t;
  ({ lum: first, rect } = await checkRestFrame(result));
  await page.screenshot({ path: join(out, `${mode}_early.png`) });
  s = await stats();
  firstChecksum = s.positionsChecksum;
  // On at 4x until the device has lost track (the hand pushes past the limit
  // 5.5 s into the script), paused there; then on at 4x. The recording's
  // clock is the logger's: a lockstep run slower than real time spreads the
  // 7 s over a minute or more of it.
  await playUntil("ghost", 4, s.replay?.t ?? 0);
  await checkGhost(result);
  ghostChecked = true;
  await page.evaluate(() => {
    window.fahrSend({ op: "replay", action: "speed", value: 4 });
    window.fahrSend({ op: "replay", action: "play" });
  });
}
result.bodies = s.bodies;
result.tongueRect = rect;
// Frames at the display rate (live): deformation frames per second after
// the first burst (a page that starts late reads its socket's backlog),
// over at least 3 s and until the FEM has made 20 states (60 s at most): a
// machine that starves the lockstep run to one or two states a second
// would otherwise leave a handful of frames to judge, and one frame more or
// less would decide.
// The server's own ticks in the same window (its /stats): it sends at most
// one deformation frame a tick, and a machine that starves it gives fewer.
const serverTicks = async () => (await (await fetch(new URL("stats", url))).json()).ticks;
if (mode === "live") {
  await page.waitForTimeout(1000);
  s = await stats();
  const f0 = s.deformFrames;
  const sim0 = s.deformSimTime;
  const ticks0 = await serverTicks();
  const t0 = Date.now();
  const femHz = Number(process.env.FEM_HZ ?? 200);
  do {
    await page.waitForTimeout(1000);
    s = await stats();
  } while (
    Date.now() - t0 < 60000 &&
    (Date.now() - t0 < 3000 || (s.deformSimTime - sim0) * femHz < 20)
  );
  const ticks1 = await serverTicks();
  const wall = (Date.now() - t0) / 1000;
  result.deformFramesPerSecond = (s.deformFrames - f0) / wall;
  result.serverTicksPerSecond = (ticks1 - ticks0) / wall;
  // The states the FEM made in that time (its simulated time over its
  // step, FEM_HZ of the scene, 200 for the shipped one): the page can
  // show no more.
  result.femStatesPerSecond = ((s.deformSimTime - sim0) * femHz) / wall;
  result.rateWindowS = wall;
}
// Let the run go on (the blade presses, the hand pushes past the limit),
// then look again.
let arrowSeen = s.arrowVisible;
let lostSeen = s.lostTrack;
let ghostSeen = s.ghostVisible;
let peakForce = s.forceN;
// The largest change from the rest frame over the watch: the blade's
// press comes when the run's script gets there, not at a fixed moment.
let largestPixelChange = 0;
let largestChecksumChange = 0;
const end = Date.now() + seconds * 1000;
while (Date.now() < end) {
  await page.waitForTimeout(250);
  s = await stats();
  if (rect) largestPixelChange = Math.max(largestPixelChange, pixelChange(first, await grab(rect)));
  largestChecksumChange = Math.max(largestChecksumChange, Math.abs(s.positionsChecksum - firstChecksum));
  arrowSeen ||= s.arrowVisible;
  lostSeen ||= s.lostTrack;
  ghostSeen ||= s.ghostVisible;
  peakForce = Math.max(peakForce, s.forceN);
  // Enough seen: the blade pressing (a push of 1 N: the intubation script
  // leans 1.6-2.4 N into the tongue from 5 s, the overshoot script more).
  if (largestPixelChange > 0.5 && arrowSeen && peakForce > PRESSED_N) break;
}
const later = rect ? await grab(rect) : [];
await page.screenshot({ path: join(out, `${mode}_later.png`) });
if (mode === "live") {
  await page.evaluate(() => window.fahrSetCamera("blade"));
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, "live_blade_view.png") });
}
result.meanPixelChange = Math.max(largestPixelChange, pixelChange(first, later));
result.vertexChecksumChange = Math.max(largestChecksumChange, Math.abs(s.positionsChecksum - firstChecksum));
result.maxStrain = s.maxStrain;
result.arrowSeen = arrowSeen;
result.lostTrackSeen = lostSeen;
result.peakForceN = peakForce;
result.limitN = s.limitN;
result.stateFrames = s.stateFrames;
result.deformFrames = s.deformFrames;
result.replay = s.replay;
result.consoleErrors = consoleErrors;
writeFileSync(join(out, `${mode}_stats.json`), JSON.stringify(s, null, 1));

// Decimated to the display rate: at most 60 a second (the server's rate),
// and at least 60 % of what the ticks could carry: a tick sends the
// newest state if one came since the last, so with states at lambda and
// ticks at mu a second, mu * (1 - exp(-lambda / mu)) frames a second for
// states arriving at random (fewer than lambda when lambda ~ mu: two states
// in one tick's interval are one frame). Both rates are the machine's: a
// starved server ticks less, a lockstep run slowed by the FEM under the
// blade or by the page's own software rendering makes fewer states, and the
// page is judged on what it was offered. The states undecimated (200 a
// second paced) break the upper bound; a page or a server that skips states
// it had, the lower.
if (mode !== "replay" && !Number.isFinite(result.femStatesPerSecond)) problems.push("no FEM time in the deformation frames");
if (mode !== "replay") {
  const mu = result.serverTicksPerSecond;
  const offered = mu > 0 ? mu * (1 - Math.exp(-result.femStatesPerSecond / mu)) : 0;
  // (At least one frame in the window, whatever was offered.)
  const floor = Math.max(1 / result.rateWindowS, 0.6 * offered);
  // (Not per tick: frames a starved page reads late from its socket's
  // backlog fall into the window too.)
  const ceiling = 65;
  if (!(result.deformFramesPerSecond >= floor && result.deformFramesPerSecond <= ceiling))
    problems.push(`${result.deformFramesPerSecond.toFixed(1)} deformation frames per second (the server ticked ${result.serverTicksPerSecond.toFixed(1)}, the FEM made ${result.femStatesPerSecond.toFixed(1)} states; at least ${floor.toFixed(1)}, at most ${ceiling.toFixed(1)})`);
}
if (result.bodies.length < 2) problems.push("fewer than two bodies drawn");
if (mode !== "replay" || !s.replay?.paused) {
  if (!(result.vertexChecksumChange > 0)) problems.push("the tongue's vertices did not change");
  if (!(result.meanPixelChange > 0.5)) problems.push(`the tongue's pixels hardly changed (${result.meanPixelChange.toFixed(2)})`);
}
if (!arrowSeen) problems.push("no force arrow");
if (!(peakForce > PRESSED_N)) problems.push(`the blade never pressed (peak |F| ${peakForce.toFixed(2)} N)`);
if (mode === "replay" && !ghostChecked) problems.push("the device never lost track in the replay");
if (mode === "live" && lostSeen && !ghostSeen) problems.push("no grey device blade while the device lost track");
if (consoleErrors.length > 0) problems.push(`console errors: ${consoleErrors.slice(0, 3).join(" | ")}`);
result.problems = problems;
console.log(JSON.stringify(result));
await browser.close();
process.exit(problems.length === 0 ? 0 : 1);
