// Debian's chromium, driven headless by playwright-core (no browser
// download), against a fahr_visualizer with a run going: the page loads,
// the scene arrives, the tongue's vertices update at the display rate, the
// force arrow appears, the pixels inside the tongue's projected bounds differ
// between an early frame and a later (pressed) one, and the console stays
// free of errors. Screenshots go to OUT_DIR.
//   node browser_check.mjs URL OUT_DIR SECONDS [live|lost|replay]
// Prints one JSON line; exit 0 if every check passed.
import { chromium } from "playwright-core";
import { writeFileSync } from "node:fs";
import { join } from "node:path";

const [url, out, secondsText, mode = "live"] = process.argv.slice(2);
const seconds = Number(secondsText ?? 10);
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

const stats = () => page.evaluate(() => JSON.parse(JSON.stringify(window.fahrStats)));
// Luminance of the canvas on a 48 x 48 grid over a rectangle.
const grab = (rect) =>
  page.evaluate((r) => {
    const src = document.querySelector("#view canvas");
    const c = document.createElement("canvas");
    c.width = 48;
    c.height = 48;
    const g = c.getContext("2d");
    g.drawImage(src, r.x, r.y, Math.max(1, r.w), Math.max(1, r.h), 0, 0, 48, 48);
    const d = g.getImageData(0, 0, 48, 48).data;
    const lum = [];
    for (let i = 0; i < d.length; i += 4) lum.push(0.299 * d[i] + 0.587 * d[i + 1] + 0.114 * d[i + 2]);
    return lum;
  }, rect);

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

const result = { mode };
let s = await waitFor((x) => x.sceneFrames > 0 && x.deformFrames > 0, 60000, "the scene and a deformation");
if (mode === "replay") {
  // The server plays the recording from its start, whenever the page comes:
  // from the beginning again, so the watch below sees it play.
  await page.evaluate(() => window.fahrSend({ op: "replay", action: "seek", value: 0 }));
  const before = s.deformFrames;
  s = await waitFor((x) => x.deformFrames > before, 10000, "a deformation after the seek");
}
result.bodies = s.bodies;
await page.evaluate(() => window.fahrSetCamera("side"));
await page.waitForTimeout(300);
s = await stats();
const rect = s.tongueRect;
result.tongueRect = rect;
const first = rect ? await grab(rect) : [];
const firstChecksum = s.positionsChecksum;
await page.screenshot({ path: join(out, `${mode}_early.png`) });
// Frames at the display rate: deformation frames per second over 3 s, after
// the first burst (a page that starts late reads its socket's backlog).
await page.waitForTimeout(1000);
s = await stats();
const f0 = s.deformFrames;
const sim0 = s.deformSimTime;
const t0 = Date.now();
await page.waitForTimeout(3000);
s = await stats();
const wall = (Date.now() - t0) / 1000;
result.deformFramesPerSecond = (s.deformFrames - f0) / wall;
// The states the FEM made in that time (its simulated time over its step,
// FEM_HZ of the scene, 200 for the shipped one): the page can show no more.
const femHz = Number(process.env.FEM_HZ ?? 200);
result.femStatesPerSecond = ((s.deformSimTime - sim0) * femHz) / wall;
// Let the run go on (the blade presses), then look again.
let arrowSeen = s.arrowVisible;
let ghostSeen = s.ghostVisible;
let lostSeen = s.lostTrack;
let peakForce = s.forceN;
// The largest change from the early frame over the watch: the blade's
// press comes when the run's script gets there, not at a fixed moment.
const pixelChange = (a, b) => {
  let d = 0;
  for (let i = 0; i < a.length; i++) d += Math.abs(a[i] - b[i]);
  return a.length ? d / a.length : 0;
};
let largestPixelChange = 0;
let largestChecksumChange = 0;
const end = Date.now() + seconds * 1000;
while (Date.now() < end) {
  await page.waitForTimeout(250);
  s = await stats();
  if (rect) largestPixelChange = Math.max(largestPixelChange, pixelChange(first, await grab(rect)));
  largestChecksumChange = Math.max(largestChecksumChange, Math.abs(s.positionsChecksum - firstChecksum));
  arrowSeen ||= s.arrowVisible;
  ghostSeen ||= s.ghostVisible;
  lostSeen ||= s.lostTrack;
  peakForce = Math.max(peakForce, s.forceN);
  if (mode === "lost" && s.ghostVisible) {
    await page.screenshot({ path: join(out, "lost_track.png") });
    break;
  }
}
const later = rect ? await grab(rect) : [];
await page.screenshot({ path: join(out, `${mode}_later.png`) });
if (mode === "live") {
  await page.evaluate(() => window.fahrSetCamera("blade"));
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, "live_blade_view.png") });
}
result.meanPixelChange = Math.max(largestPixelChange, pixelChange(first, later));
result.vertexChecksumChange = Math.max(
  largestChecksumChange,
  Math.abs(s.positionsChecksum - firstChecksum),
);
result.maxStrain = s.maxStrain;
result.arrowSeen = arrowSeen;
result.ghostSeen = ghostSeen;
result.lostTrackSeen = lostSeen;
result.peakForceN = peakForce;
result.limitN = s.limitN;
result.stateFrames = s.stateFrames;
result.deformFrames = s.deformFrames;
result.replay = s.replay;
result.consoleErrors = consoleErrors;
writeFileSync(join(out, `${mode}_stats.json`), JSON.stringify(s, null, 1));

// Decimated to the display rate, 30-60 a second (the server sends at most
// 60), or 80 % of the states the FEM made when it made fewer than that (a
// loaded machine). A software-rendered page beside the whole station on two
// cores draws 39-60 a second, so 30 is the floor, not 80 % of 60.
if (mode !== "replay" && !Number.isFinite(result.femStatesPerSecond)) problems.push("no FEM time in the deformation frames");
if (mode !== "replay") {
  const floor = Math.max(2, Math.min(30, 0.8 * result.femStatesPerSecond));
  if (result.deformFramesPerSecond < floor || result.deformFramesPerSecond > 65)
    problems.push(`${result.deformFramesPerSecond.toFixed(1)} deformation frames per second (the FEM made ${result.femStatesPerSecond.toFixed(1)}; at least ${floor.toFixed(1)}, at most 60)`);
}
if (result.bodies.length < 2) problems.push("fewer than two bodies drawn");
if (mode !== "replay" || !s.replay?.paused) {
  if (!(result.vertexChecksumChange > 0)) problems.push("the tongue's vertices did not change");
  if (!(result.meanPixelChange > 0.5)) problems.push(`the tongue's pixels hardly changed (${result.meanPixelChange.toFixed(2)})`);
}
if (!arrowSeen) problems.push("no force arrow");
if (lostSeen && !ghostSeen) problems.push("no grey device blade while the device lost track");
if (mode === "lost" && !lostSeen) problems.push("the device never lost track");
if (consoleErrors.length > 0) problems.push(`console errors: ${consoleErrors.slice(0, 3).join(" | ")}`);
result.problems = problems;
console.log(JSON.stringify(result));
await browser.close();
process.exit(problems.length === 0 ? 0 : 1);
