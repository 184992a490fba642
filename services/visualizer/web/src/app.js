// fahr_visualizer's page: the scene drawn with three.js from the server's
// frames (docs/design/visualizer.md has their layout), live plots with uPlot,
// replay controls and the mouse as the device. It computes nothing of the
// simulation: strain, poses and forces come as the services computed them.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";

const SCENE_FRAME = 1;
const DEFORM_FRAME = 2;
const STRAIN_FULL_SCALE = 0.3; // the colour map's top, Green strain
const FORCE_ARROW_M_PER_N = 0.006;

// What tests read (tests/visualizer/js/browser_check.mjs).
const stats = {
  connected: false,
  hello: null,
  sceneFrames: 0,
  deformFrames: 0,
  stateFrames: 0,
  deformTimes: [],
  positionsChecksum: 0,
  deformSimTime: 0, // the FEM's simulated time of the last deformation frame, s
  stateSimTime: -1, // the newest state frame's ForceCommand's simulated time, s; -1: none
  maxStrain: 0,
  arrowVisible: false,
  ghostVisible: false,
  lostTrack: false,
  forceN: 0,
  limitN: 0,
  replay: null,
  refusals: [],
  tongueRect: null,
  ghostRect: null, // the grey device blade's projected bounds while drawn, canvas pixels
  bodies: [],
  glottic: null, // the newest GlotticView: percent, force_n, peak_force_n, eye, target
  camera: "overview",
};
window.fahrStats = stats;

// --- three.js scene ------------------------------------------------------
const view = document.getElementById("view");
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
// Drawn on demand: a frame when something shown may have changed (a frame
// from the server, a toggle, the camera, the window), not every display
// refresh. A paused replay or a quiet run then costs no drawing, which on a
// machine drawing in software (a lab PC without a GPU driver, CI's
// SwiftShader) is a core kept for the simulation beside it.
let needsRender = true;
function invalidate() {
  needsRender = true;
}
renderer.setPixelRatio(1);
renderer.setClearColor(0x1d2024);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 10);
camera.position.set(0.06, 0.05, 0.16);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(-0.03, 0, 0);
controls.addEventListener("change", invalidate);
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
sun.position.set(0.3, 0.5, 0.4);
scene.add(sun);

function resize() {
  const w = view.clientWidth;
  const h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  invalidate();
}
window.addEventListener("resize", resize);
resize();

const bodies = new Map(); // body id -> { role, mesh, geometry, ... }
let tool = null; // { proxy, ghost }
const contactGroup = new THREE.Group();
scene.add(contactGroup);
const sphereGroup = new THREE.Group();
sphereGroup.visible = false; // the "spheres" toggle; each level has its own below
scene.add(sphereGroup);
const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 1, 0), new THREE.Vector3(), 0.01, 0x40d040, 0.006, 0.003);
arrow.visible = false;
scene.add(arrow);

const show = { anatomy: true, spheres: false, contacts: true, arrow: true, ghost: true };

// Strain -> colour: blue, cyan, green, yellow, red over [0, full scale].
const ramp = [
  [0.19, 0.31, 0.78],
  [0.19, 0.75, 0.75],
  [0.31, 0.82, 0.31],
  [0.88, 0.88, 0.25],
  [0.88, 0.19, 0.19],
];
function strainColour(e, out, i) {
  const x = Math.min(1, Math.max(0, e / STRAIN_FULL_SCALE)) * (ramp.length - 1);
  const k = Math.min(ramp.length - 2, Math.floor(x));
  const f = x - k;
  for (let c = 0; c < 3; c++) out[3 * i + c] = ramp[k][c] * (1 - f) + ramp[k + 1][c] * f;
}

function readScene(buf) {
  const u = new Uint32Array(buf, 0, 7);
  const [, bodyId, role, nv, nt, ns, nameLen] = u;
  const name = new TextDecoder().decode(new Uint8Array(buf, 28, nameLen));
  let off = 28 + Math.ceil(nameLen / 4) * 4;
  const pos = new Float32Array(buf.slice(off, off + nv * 12));
  off += nv * 12;
  const tris = new Uint32Array(buf.slice(off, off + nt * 12));
  off += nt * 12;
  const spheres = new Float32Array(buf.slice(off, off + ns * 16));
  off += ns * 16;
  // The spheres' node links and levels (deformable bodies; none: at rest).
  let links = null;
  if (ns > 0) {
    const nl = new Uint32Array(buf, off, 1)[0];
    off += 4;
    if (nl > 0) {
      const first = new Uint32Array(buf.slice(off, off + ns * 4));
      off += ns * 4;
      const nodes = new Uint32Array(buf.slice(off, off + nl * 4));
      off += nl * 4;
      const weights = new Float32Array(buf.slice(off, off + nl * 4));
      off += nl * 4;
      const levels = new Uint8Array(buf.slice(off, off + ns));
      links = { first, nodes, weights, levels };
    }
  }
  return { bodyId, role, name, pos, tris, spheres, links };
}

function addBody(b) {
  const old = bodies.get(b.bodyId);
  if (old) {
    for (const m of old.meshes) scene.remove(m);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(b.pos, 3));
  geometry.setIndex(new THREE.BufferAttribute(b.tris, 1));
  geometry.computeVertexNormals();
  const entry = { role: b.role, name: b.name, geometry, meshes: [] };
  if (b.role === 0) {
    // The deformable body: dynamic positions, coloured by strain.
    geometry.attributes.position.setUsage(THREE.DynamicDrawUsage);
    const colours = new Float32Array(b.pos.length);
    for (let i = 0; i < b.pos.length / 3; i++) strainColour(0, colours, i);
    geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide }));
    entry.meshes.push(mesh);
    entry.rest = b.pos.slice();
    scene.add(mesh);
    buildSpheres(b);
  } else if (b.role === 1) {
    // The tool: the blade at the proxy pose, and a translucent grey copy at
    // the device pose while the device has lost track.
    const proxy = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: 0xc8ccd4, metalness: 0.6, roughness: 0.35 }));
    const ghost = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ color: 0x909090, transparent: true, opacity: 0.35, depthWrite: false }));
    ghost.visible = false;
    proxy.matrixAutoUpdate = false;
    ghost.matrixAutoUpdate = false;
    entry.meshes.push(proxy, ghost);
    scene.add(proxy, ghost);
    geometry.computeBoundingBox();
    const size = new THREE.Vector3();
    geometry.boundingBox.getSize(size);
    tool = { proxy, ghost };
  } else {
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ color: 0xd8b0a0, transparent: true, opacity: 0.45, side: THREE.DoubleSide, depthWrite: false }));
    mesh.visible = show.anatomy;
    entry.meshes.push(mesh);
    scene.add(mesh);
  }
  bodies.set(b.bodyId, entry);
  stats.bodies = [...bodies.values()].map((e) => ({ name: e.name, role: e.role }));
}

// --- AIST spheres: one instanced mesh per level, moved with the tissue ----
const LEVEL_COLOURS = [0x70a0ff, 0x70e0a0, 0xe0c070, 0xe070d0];
const HUGGING = 255;
let sphereSets = []; // { level, name, indices, mesh }
let sphereSource = null; // { spheres, links }
function buildSpheres(b) {
  sphereGroup.clear();
  sphereSets = [];
  sphereSource = { spheres: b.spheres, links: b.links };
  const count = b.spheres.length / 4;
  if (count === 0) return;
  const byLevel = new Map();
  for (let i = 0; i < count; i++) {
    const level = b.links ? b.links.levels[i] : 0;
    if (!byLevel.has(level)) byLevel.set(level, []);
    byLevel.get(level).push(i);
  }
  // Coarse spheres: thousands of them, drawn in software on machines without a GPU.
  const geom = new THREE.SphereGeometry(1, 8, 5);
  for (const level of [...byLevel.keys()].sort((a, c) => a - c)) {
    const indices = byLevel.get(level);
    const colour = level === HUGGING ? 0xff9060 : LEVEL_COLOURS[level % LEVEL_COLOURS.length];
    const mat = new THREE.MeshBasicMaterial({ color: colour, wireframe: true, transparent: true, opacity: 0.35 });
    const mesh = new THREE.InstancedMesh(geom, mat, indices.length);
    const name = level === HUGGING ? "hugging" : `level ${level}`;
    const set = { level, name, indices, mesh };
    mesh.visible = show.spheres && sphereLevelShown(name);
    sphereSets.push(set);
    sphereGroup.add(mesh);
  }
  placeSpheres(null);
  makeSphereToggles();
}
const hiddenLevels = new Set();
function sphereLevelShown(name) {
  return !hiddenLevels.has(name);
}
// Sphere centres from the node positions (null: at rest): c = sum w x.
const sphereMatrix = new THREE.Matrix4();
function placeSpheres(pos) {
  if (!sphereSource) return;
  const { spheres, links } = sphereSource;
  for (const set of sphereSets) {
    if (!set.mesh.visible && pos) continue;
    set.indices.forEach((i, k) => {
      let x = spheres[4 * i];
      let y = spheres[4 * i + 1];
      let z = spheres[4 * i + 2];
      if (pos && links) {
        const end = i + 1 < links.first.length ? links.first[i + 1] : links.nodes.length;
        x = y = z = 0;
        for (let l = links.first[i]; l < end; l++) {
          const n = links.nodes[l];
          const w = links.weights[l];
          x += w * pos[3 * n];
          y += w * pos[3 * n + 1];
          z += w * pos[3 * n + 2];
        }
      }
      const r = spheres[4 * i + 3];
      sphereMatrix.makeScale(r, r, r).setPosition(x, y, z);
      set.mesh.setMatrixAt(k, sphereMatrix);
    });
    set.mesh.instanceMatrix.needsUpdate = true;
  }
  stats.sphereLevels = sphereSets.map((s) => ({ name: s.name, count: s.indices.length, visible: s.mesh.visible }));
  stats.spheresMoved = !!(pos && links);
}
function makeSphereToggles() {
  const row = document.getElementById("sphere-levels");
  row.textContent = "";
  for (const set of sphereSets) {
    const b = document.createElement("button");
    b.textContent = `${set.name} (${set.indices.length})`;
    b.className = sphereLevelShown(set.name) ? "on" : "";
    b.onclick = () => {
      if (hiddenLevels.has(set.name)) hiddenLevels.delete(set.name);
      else hiddenLevels.add(set.name);
      b.className = sphereLevelShown(set.name) ? "on" : "";
      updateSphereVisibility();
    };
    row.appendChild(b);
  }
}
let lastPositions = null;
function updateSphereVisibility() {
  invalidate();
  for (const set of sphereSets) set.mesh.visible = show.spheres && sphereLevelShown(set.name);
  placeSpheres(lastPositions);
}

function applyDeformation(buf) {
  const u = new Uint32Array(buf, 0, 4);
  const bodyId = u[1];
  const n = u[2];
  const entry = bodies.get(bodyId);
  if (!entry || entry.role !== 0) return;
  const pos = new Float32Array(buf, 24, n * 3);
  const strain = new Float32Array(buf, 24 + n * 12, n);
  const attr = entry.geometry.attributes.position;
  if (attr.count !== n) return;
  attr.array.set(pos);
  attr.needsUpdate = true;
  lastPositions = attr.array;
  if (show.spheres) placeSpheres(lastPositions);
  const colours = entry.geometry.attributes.color;
  let max = 0;
  let sum = 0;
  for (let i = 0; i < n; i++) {
    strainColour(strain[i], colours.array, i);
    if (strain[i] > max) max = strain[i];
    sum += pos[3 * i + 1];
  }
  colours.needsUpdate = true;
  entry.geometry.computeVertexNormals();
  entry.geometry.computeBoundingSphere();
  stats.maxStrain = max;
  stats.positionsChecksum = sum;
  stats.deformSimTime = new Float64Array(buf, 16, 1)[0];
  stats.deformFrames++;
  stats.deformTimes.push(performance.now());
  if (stats.deformTimes.length > 200) stats.deformTimes.shift();
}

function poseMatrix(p, q) {
  const m = new THREE.Matrix4();
  m.compose(new THREE.Vector3(p[0], p[1], p[2]), new THREE.Quaternion(q[1], q[2], q[3], q[0]), new THREE.Vector3(1, 1, 1));
  return m;
}

// --- plots -----------------------------------------------------------------
const WINDOW_S = 20;
function makePlot(id, series) {
  const el = document.getElementById(id);
  const opts = {
    width: 320,
    height: 110,
    legend: { show: true },
    scales: { x: { time: false } },
    axes: [{ stroke: "#889", grid: { stroke: "#333" } }, { stroke: "#889", grid: { stroke: "#333" }, size: 40 }],
    series: [{}, ...series.map(([label, stroke]) => ({ label, stroke, width: 1.5 }))],
  };
  const data = [[], ...series.map(() => [])];
  const plot = new uPlot(opts, data, el);
  return { plot, data };
}
const plots = {
  rate: makePlot("plot-rate", [["haptic", "#6cf"]]),
  force: makePlot("plot-force", [["|F|", "#fc6"], ["limit", "#f66"]]),
  latency: makePlot("plot-latency", [["p50", "#8e8"], ["p99", "#e8e"]]),
};
const t0 = performance.now();
function pushPoint(p, values) {
  const t = (performance.now() - t0) / 1000;
  p.data[0].push(t);
  values.forEach((v, i) => p.data[i + 1].push(v));
  while (p.data[0].length > 0 && p.data[0][0] < t - WINDOW_S) p.data.forEach((a) => a.shift());
}
let plotDirty = false;
setInterval(() => {
  if (!plotDirty) return;
  plotDirty = false;
  for (const p of Object.values(plots)) p.plot.setData(p.data);
}, 250);

// --- state frames ----------------------------------------------------------
function forceColour(share) {
  const s = Math.min(1, Math.max(0, share));
  return new THREE.Color().setHSL((1 - s) * 0.33, 0.85, 0.5);
}

let lastPlot = 0;
function applyState(s) {
  stats.stateFrames++;
  const cmd = s.command[0];
  const dev = s.device[0];
  const limit = dev ? dev.limit_n : 0;
  stats.limitN = limit;
  // No ForceCommand (before the first, or after a replay's seek): the
  // blade's pose is unknown, and it is not drawn rather than drawn at the
  // world's origin.
  if (tool) tool.proxy.visible = !!cmd;
  stats.stateSimTime = cmd ? cmd.t : -1;
  if (tool && cmd) {
    tool.proxy.matrix.copy(poseMatrix(cmd.proxy.p, cmd.proxy.q));
    tool.proxy.matrixWorldNeedsUpdate = true;
    stats.lostTrack = cmd.lost_track;
    if (cmd.lost_track && dev) {
      tool.ghost.matrix.copy(poseMatrix(dev.pose.p, dev.pose.q));
      tool.ghost.matrixWorldNeedsUpdate = true;
    }
    tool.ghost.visible = !!cmd.lost_track && !!dev && show.ghost;
    stats.ghostVisible = tool.ghost.visible;
    document.getElementById("lost").style.display = cmd.lost_track ? "block" : "none";
  }
  if (cmd) {
    const f = new THREE.Vector3(...cmd.force);
    const mag = f.length();
    stats.forceN = mag;
    if (mag > 1e-3 && show.arrow) {
      // The force on the hand, drawn from the blade's proxy position.
      arrow.position.set(...cmd.proxy.p);
      arrow.setDirection(f.clone().normalize());
      arrow.setLength(Math.max(0.004, mag * FORCE_ARROW_M_PER_N), 0.004, 0.002);
      arrow.setColor(forceColour(limit > 0 ? mag / limit : 1));
      arrow.visible = true;
    } else {
      arrow.visible = false;
    }
    stats.arrowVisible = stats.arrowVisible || arrow.visible;
  }
  contactGroup.clear();
  if (show.contacts) {
    for (const set of s.contacts) {
      for (const c of set.contacts) {
        const dot = new THREE.Mesh(contactDot, c[2] === 1 ? frozenMat : activeMat);
        dot.position.set(c[3], c[4], c[5]);
        contactGroup.add(dot);
      }
    }
  }
  const now = performance.now();
  if (now - lastPlot > 100) {
    lastPlot = now;
    const haptic = s.services.find((x) => x.name === "haptic");
    const gateway = s.services.find((x) => x.name === "device_gateway");
    if (haptic) pushPoint(plots.rate, [haptic.rate_hz]);
    if (cmd) pushPoint(plots.force, [stats.forceN, limit]);
    if (gateway && gateway.metrics) pushPoint(plots.latency, [gateway.metrics.motion_to_force_p50_ms ?? 0, gateway.metrics.motion_to_force_p99_ms ?? 0]);
    plotDirty = true;
  }
  const glottic = s.glottic && s.glottic[0];
  stats.glottic = glottic ?? null;
  if (glottic) {
    document.getElementById("pogo").textContent =
      `${glottic.percent.toFixed(0)} % of the glottic opening seen | blade on tissue ${glottic.force_n.toFixed(2)} N (peak ${glottic.peak_force_n.toFixed(2)} N)`;
    if (stats.camera === "blade") setCamera("blade");
  }
  const lines = [
    `${stats.hello ? stats.hello.mode : "?"} | frames: ${stats.deformFrames} deform, ${stats.stateFrames} state`,
    `|F| ${stats.forceN.toFixed(2)} N of ${limit.toFixed(1)} N${cmd && cmd.lost_track ? "  LOST TRACK" : ""}`,
    `max Green strain ${stats.maxStrain.toFixed(3)}  contacts ${s.contacts.reduce((n, c) => n + c.contacts.length, 0)}`,
    ...s.services.map((x) => `${x.name.padEnd(15)} ${x.rate_hz.toFixed(0).padStart(5)} Hz`),
  ];
  document.getElementById("status").textContent = lines.join("\n");
}
const contactDot = new THREE.SphereGeometry(0.0008, 8, 6);
const activeMat = new THREE.MeshBasicMaterial({ color: 0xff3030 });
const frozenMat = new THREE.MeshBasicMaterial({ color: 0x30a0ff });

// --- camera presets --------------------------------------------------------
function setCamera(name) {
  stats.camera = name;
  invalidate();
  if (name === "blade" && stats.glottic) {
    // The laryngoscopist's view: from the scene's eye point on the blade
    // (glottic_view.eye_in_tool_m) towards the glottic opening, the eye the
    // glottic view score is computed from; it follows the blade.
    camera.position.set(...stats.glottic.eye);
    controls.target.set(...stats.glottic.target);
  } else {
    const presets = {
      overview: [[0.06, 0.05, 0.16], [-0.03, 0, 0]],
      side: [[-0.03, 0.0, 0.16], [-0.03, 0, 0]],
      top: [[-0.03, 0.16, 0.001], [-0.03, 0, 0]],
      front: [[0.14, 0.02, 0.0], [-0.03, 0, 0]],
    };
    // "blade" without a glottic view (the scene defines no eye): the front view.
    const [p, t] = presets[name] ?? presets.front;
    camera.position.set(...p);
    controls.target.set(...t);
  }
  controls.update();
}
window.fahrSetCamera = setCamera;
for (const name of ["overview", "side", "top", "front", "blade"]) {
  const b = document.createElement("button");
  b.textContent = name;
  b.onclick = () => setCamera(name);
  document.getElementById("cameras").appendChild(b);
}
const toggleButtons = {};
function setShow(key, on) {
  if (!(key in show)) return;
  invalidate();
  show[key] = on;
  toggleButtons[key].className = on ? "on" : "";
  sphereGroup.visible = show.spheres;
  updateSphereVisibility();
  for (const e of bodies.values()) if (e.role === 2) e.meshes.forEach((m) => (m.visible = show.anatomy));
  if (!show.arrow) arrow.visible = false;
  if (!show.contacts) contactGroup.clear();
  if (tool) tool.ghost.visible = show.ghost && stats.lostTrack;
  stats.ghostVisible = !!tool && tool.ghost.visible;
}
window.fahrShow = setShow; // what the buttons do, for tests
for (const key of Object.keys(show)) {
  const b = document.createElement("button");
  b.textContent = key;
  b.className = show[key] ? "on" : "";
  b.onclick = () => setShow(key, !show[key]);
  toggleButtons[key] = b;
  document.getElementById("toggles").appendChild(b);
}
document.getElementById("strainmax").textContent = STRAIN_FULL_SCALE.toFixed(2);

// --- the connection --------------------------------------------------------
let ws = null;
function send(obj) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(obj));
}
window.fahrSend = send;

function connect() {
  ws = new WebSocket(`ws://${location.host}/ws`);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => (stats.connected = true);
  ws.onclose = () => {
    stats.connected = false;
    setTimeout(connect, 1000);
  };
  ws.onmessage = (ev) => {
    invalidate();
    if (typeof ev.data !== "string") {
      const kind = new Uint32Array(ev.data, 0, 1)[0];
      if (kind === SCENE_FRAME) {
        stats.sceneFrames++;
        addBody(readScene(ev.data));
      } else if (kind === DEFORM_FRAME) {
        applyDeformation(ev.data);
      }
      return;
    }
    const msg = JSON.parse(ev.data);
    if (msg.op === "state") applyState(msg);
    else if (msg.op === "hello") onHello(msg);
    else if (msg.op === "replay") onReplay(msg);
    else if (msg.op === "refused") {
      stats.refusals.push(msg);
      document.getElementById("refusal").textContent = `refused: ${msg.reason}`;
    }
  };
}

function onHello(msg) {
  stats.hello = msg;
  document.getElementById("replay").style.display = msg.mode === "replay" ? "block" : "none";
  document.getElementById("mouse").style.display = msg.remote_input ? "block" : "none";
}

// --- replay ------------------------------------------------------------------
const slider = document.getElementById("slider");
let sliding = false;
function onReplay(msg) {
  stats.replay = msg;
  if (!sliding && msg.duration > 0) slider.value = String(Math.round((msg.t / msg.duration) * 1000));
  document.getElementById("pause").textContent = msg.paused ? "play" : "pause";
  document.getElementById("replaytime").textContent = `${msg.t.toFixed(2)} / ${msg.duration.toFixed(2)} s`;
}
slider.addEventListener("input", () => (sliding = true));
slider.addEventListener("change", () => {
  sliding = false;
  if (stats.replay) send({ op: "replay", action: "seek", value: (Number(slider.value) / 1000) * stats.replay.duration });
});
document.getElementById("pause").onclick = () => send({ op: "replay", action: stats.replay && stats.replay.paused ? "play" : "pause" });
document.getElementById("speed").onchange = (e) => send({ op: "replay", action: "speed", value: Number(e.target.value) });

// --- the mouse as the device -------------------------------------------------
// Drag on the view's plane moves the device's x (right) and y (up), the
// wheel its depth z; holding P presses the button. Poses are in the device's
// frame; the gateway's remote back-end clamps them to its workspace.
const mouse = { on: false, p: [0, 0, 0], buttons: 0, dragging: false, last: null, lastSent: 0 };
const HALF_WORKSPACE_M = 0.08;
document.getElementById("mousebtn").onclick = (e) => {
  mouse.on = !mouse.on;
  controls.enabled = !mouse.on;
  e.target.textContent = mouse.on ? "on" : "off";
  e.target.className = mouse.on ? "on" : "";
};
function clampWorkspace(v) {
  return Math.max(-HALF_WORKSPACE_M, Math.min(HALF_WORKSPACE_M, v));
}
function sendPose() {
  const now = performance.now();
  if (now - mouse.lastSent < 16) return;
  mouse.lastSent = now;
  send({ op: "pose", p: mouse.p, q: [1, 0, 0, 0], buttons: mouse.buttons });
}
renderer.domElement.addEventListener("pointerdown", (e) => {
  if (!mouse.on) return;
  mouse.dragging = true;
  mouse.last = [e.clientX, e.clientY];
});
window.addEventListener("pointerup", () => (mouse.dragging = false));
renderer.domElement.addEventListener("pointermove", (e) => {
  if (!mouse.on || !mouse.dragging) return;
  const scale = 0.0003; // m per pixel
  mouse.p[0] = clampWorkspace(mouse.p[0] + (e.clientX - mouse.last[0]) * scale);
  mouse.p[1] = clampWorkspace(mouse.p[1] - (e.clientY - mouse.last[1]) * scale);
  mouse.last = [e.clientX, e.clientY];
  sendPose();
});
renderer.domElement.addEventListener("wheel", (e) => {
  if (!mouse.on) return;
  e.preventDefault();
  mouse.p[2] = clampWorkspace(mouse.p[2] + Math.sign(e.deltaY) * 0.002);
  sendPose();
}, { passive: false });
window.addEventListener("keydown", (e) => {
  if (mouse.on && e.key === "p") {
    mouse.buttons = 1;
    sendPose();
  }
});
window.addEventListener("keyup", (e) => {
  if (mouse.on && e.key === "p") {
    mouse.buttons = 0;
    sendPose();
  }
});

// --- drawing -------------------------------------------------------------------
// A world-frame box's projected bounds on the canvas, pixels.
function screenRect(b) {
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (const x of [b.min.x, b.max.x]) for (const y of [b.min.y, b.max.y]) for (const z of [b.min.z, b.max.z]) {
    const v = new THREE.Vector3(x, y, z).project(camera);
    const px = ((v.x + 1) / 2) * renderer.domElement.width;
    const py = ((1 - v.y) / 2) * renderer.domElement.height;
    x0 = Math.min(x0, px); y0 = Math.min(y0, py); x1 = Math.max(x1, px); y1 = Math.max(y1, py);
  }
  // Clipped to the canvas: a long body (the blade's handle) runs off it.
  x0 = Math.max(0, x0);
  y0 = Math.max(0, y0);
  x1 = Math.min(renderer.domElement.width, x1);
  y1 = Math.min(renderer.domElement.height, y1);
  return { x: x0, y: y0, w: Math.max(0, x1 - x0), h: Math.max(0, y1 - y0) };
}
function tongueRect() {
  for (const e of bodies.values()) {
    if (e.role !== 0) continue;
    e.geometry.computeBoundingBox();
    return screenRect(e.geometry.boundingBox);
  }
  return null;
}
function frame() {
  controls.update();
  if (needsRender) {
    needsRender = false;
    renderer.render(scene, camera);
  }
  stats.tongueRect = tongueRect();
  stats.ghostRect = tool && tool.ghost.visible
    ? screenRect(tool.ghost.geometry.boundingBox.clone().applyMatrix4(tool.ghost.matrix))
    : null;
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
connect();
