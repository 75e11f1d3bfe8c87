// Dupin configurator: a thin shell. Geometry and rendering live in Rust (../crates/dupin-web);
// this file wires DOM events, the URL hash and the frame loop.
import init, { Session, Viewer, sceneNames, torusMesh } from './pkg/dupin_web.js';
import { initTeach } from './teach.js';
import { initHexd2d } from './hexd2d.js';
import { initPresent } from './present.js';

const $ = (id) => document.querySelector(`[data-testid="${id}"]`) ?? document.getElementById(id);
const statusEl = $('status');
const metricsEl = $('metrics');
const canvas = $('canvas');

// Scenes available in this build. Each has typed parameters shown as numeric fields.
const SCENES = {
  torus: {
    label: 'Torus (surface preview)',
    params: { R: { label: 'R', value: 2, min: 0.05, max: 100 }, r: { label: 'r', value: 0.7, min: 0.01, max: 100 } },
    build: (p) => torusMesh(p.R, p.r, 96, 48),
  },
};

let viewer = null;
let mesh = null;        // MeshData on screen
let session = null;     // Session of a stepped scene (null for the surface preview)
let playing = false;
let dirty = true;

function showStatus(text, isError = false) {
  statusEl.textContent = text;
  statusEl.classList.toggle('error', isError);
}

function showMetrics(m) {
  metricsEl.dataset.phase = m.phase;
  metricsEl.dataset.iteration = String(m.iteration);
  metricsEl.dataset.faces = String(m.faces);
  metricsEl.dataset.maxPlanarity = String(m.maxPlanarity);
  const rows = [['phase', m.phase], ['layer', m.layer ?? 0], ['iteration', m.iteration], ['faces', m.faces],
    ['vertices', m.vertices], ['max planarity', m.maxPlanarity.toExponential(2)],
    ['invalid faces', m.invalidFaces ?? 0], ['step time', m.ms === undefined ? '–' : `${m.ms.toFixed(1)} ms`]];
  metricsEl.replaceChildren(...rows.flatMap(([k, v]) => {
    const dt = document.createElement('dt'); dt.textContent = k;
    const dd = document.createElement('dd'); dd.textContent = String(v);
    return [dt, dd];
  }));
}

// ---- configuration <-> URL hash -------------------------------------------------------------
function readHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  const name = h.get('scene');
  const scene = SCENES[name] || STEPPED.includes(name) ? name : 'torus';
  const params = {};
  for (const [k, spec] of Object.entries(SCENES[scene]?.params ?? {})) {
    const v = Number(h.get(k));
    params[k] = h.has(k) && Number.isFinite(v) ? v : spec.value;
  }
  return { scene, params, backend: h.get('backend') === 'webgl2' ? 'webgl2' : 'auto' };
}

function writeHash(cfg) {
  const h = new URLSearchParams({ scene: cfg.scene, ...cfg.params });
  if (cfg.backend !== 'auto') h.set('backend', cfg.backend);
  history.replaceState(null, '', '#' + h.toString());
}

let config = { scene: 'torus', params: {}, backend: 'auto' };

function buildControls() {
  const select = $('scene-select');
  const preview = Object.entries(SCENES).map(([name, s]) => new Option(s.label, name));
  const stepped = STEPPED.map((name) => new Option(name, name));
  select.replaceChildren(...preview, ...stepped);
  select.value = config.scene;
  const box = document.getElementById('params');
  box.replaceChildren();
  for (const [k, spec] of Object.entries(SCENES[config.scene]?.params ?? {})) {
    const label = document.createElement('label');
    label.textContent = spec.label;
    const input = document.createElement('input');
    Object.assign(input, { type: 'number', step: 'any', min: spec.min, max: spec.max, value: config.params[k] });
    input.dataset.testid = `param-${k}`;
    const msg = document.createElement('span');
    msg.className = 'field-error';
    input.addEventListener('change', () => {
      const v = Number(input.value);
      const ok = input.value.trim() !== '' && Number.isFinite(v) && v >= spec.min && v <= spec.max;
      input.classList.toggle('invalid', !ok);
      msg.textContent = ok ? '' : `${spec.label} must be a number in [${spec.min}, ${spec.max}]`;
      if (ok) { config.params[k] = v; writeHash(config); loadScene(false); }
    });
    label.append(input, msg);
    box.append(label);
  }
}

function showError(e) {
  showStatus(`${viewer.backend} · ${e.message ?? e}`, true);
}

function showMesh(next, reframe) {
  viewer.setMesh(next, reframe);
  mesh?.free();
  mesh = next;
  dirty = true;
}

// Selecting a scene starts it from its first step; the surface preview is computed at once.
function loadScene(reframe) {
  setPlaying(false);
  session?.free();
  session = null;
  lastFaces = 0;
  lastPhase = '';
  userMoved = false;
  try {
    if (SCENES[config.scene]) {
      showMesh(SCENES[config.scene].build(config.params), reframe);
      showMetrics({ phase: 'done', iteration: 0, faces: mesh.triangleCount, vertices: mesh.vertexCount, maxPlanarity: 0 });
    } else {
      session = new Session({ scene: config.scene });
      step(reframe);
    }
    showStatus(viewer.backend);
  } catch (e) {
    showError(e);
  }
  updateButtons();
}

function step(reframe = false) {
  if (!session) return;
  try {
    const t = performance.now();
    const m = session.step();
    m.ms = performance.now() - t;
    // Frame the growing mesh at its first step and once more when its last layer is in, unless
    // the user has taken the camera.
    const grown = lastPhase === 'triangulation' && m.phase !== 'triangulation';
    showMesh(session.mesh(), reframe || lastFaces === 0 || (grown && !userMoved));
    lastFaces = m.faces;
    lastPhase = m.phase;
    showMetrics(m);
  } catch (e) {
    setPlaying(false);
    showError(e);
  }
  updateButtons();
}
let lastFaces = 0;
let lastPhase = '';
let userMoved = false;

function setPlaying(on) {
  playing = on && !!session && !session.done();
  $('play').textContent = playing ? 'Pause' : 'Play';
  if (playing) setTimeout(playLoop, 0);
}

function playLoop() {
  if (!playing) return;
  step();
  if (session?.done()) setPlaying(false);
  else setTimeout(playLoop, 30);
}

function updateButtons() {
  const stepped = !!session;
  $('step').disabled = !stepped || session.done();
  $('play').disabled = !stepped || session.done();
  $('reset').disabled = !stepped;
}

// ---- orbit: mouse drag, wheel, touch (one finger orbits, two pinch) --------------------------
function wireInput() {
  const pointers = new Map();
  let pinch = 0;
  canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); pointers.set(e.pointerId, e); userMoved = true; });
  canvas.addEventListener('pointermove', (e) => {
    const prev = pointers.get(e.pointerId);
    if (!prev) return;
    pointers.set(e.pointerId, e);
    if (pointers.size === 1) {
      viewer.orbit((e.clientX - prev.clientX) * 0.008, (e.clientY - prev.clientY) * 0.008);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const d = Math.hypot(a.clientX - b.clientX, a.clientY - b.clientY);
      if (pinch > 0) viewer.zoom(pinch / d);
      pinch = d;
    }
    dirty = true;
  });
  const up = (e) => { pointers.delete(e.pointerId); pinch = 0; };
  canvas.addEventListener('pointerup', up);
  canvas.addEventListener('pointercancel', up);
  canvas.addEventListener('wheel', (e) => { e.preventDefault(); userMoved = true; viewer.zoom(Math.exp(e.deltaY * 0.001)); dirty = true; }, { passive: false });
}

function frame() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; viewer.resize(w, h); dirty = true; }
  viewer.poll();
  if (dirty) {
    dirty = false;
    try {
      viewer.render();
      if (document.body.dataset.ready !== 'true') {
        document.body.dataset.firstFrameMs = performance.now().toFixed(0);
        document.body.dataset.ready = 'true';
      }
    } catch (e) {
      showStatus(`${viewer.backend} · ${e.message ?? e}`, true);
    }
  }
  requestAnimationFrame(frame);
}

/** Renders the view at `scale` x the canvas size on the GPU and returns a PNG blob. */
async function snapshotPng(scale = 1) {
  const image = await viewer.snapshot(scale);
  const c = new OffscreenCanvas(image.width, image.height);
  c.getContext('2d').putImageData(image, 0, 0);
  return c.convertToBlob({ type: 'image/png' });
}

// For tests and scripting: pixels as the page draws them (headless Chromium composites no WebGPU
// canvas into its own screenshots).
window.dupin = {
  snapshotDataUrl: async (scale = 1) => {
    const blob = await snapshotPng(scale);
    return new Promise((resolve) => { const r = new FileReader(); r.onload = () => resolve(r.result); r.readAsDataURL(blob); });
  },
};

function download(name, data, type) {
  const url = URL.createObjectURL(data instanceof Blob ? data : new Blob([data], { type }));
  const a = Object.assign(document.createElement('a'), { href: url, download: name });
  a.click();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

let STEPPED = [];

async function main() {
  try {
    await init();
    STEPPED = sceneNames();
    config = readHash();
    canvas.width = Math.max(1, canvas.clientWidth);
    canvas.height = Math.max(1, canvas.clientHeight);
    viewer = await Viewer.create(canvas, config.backend === 'webgl2');
  } catch (e) {
    showStatus(`Cannot start: ${e.message ?? e}`, true);
    return;
  }
  buildControls();
  initTeach();
  initHexd2d();
  initPresent(() => mesh);
  $('scene-select').addEventListener('change', (e) => {
    config = { scene: e.target.value, params: {}, backend: config.backend };
    for (const [k, s] of Object.entries(SCENES[config.scene]?.params ?? {})) config.params[k] = s.value;
    writeHash(config);
    buildControls();
    loadScene(true);
  });
  window.addEventListener('hashchange', () => { config = readHash(); buildControls(); loadScene(true); });
  $('step').addEventListener('click', () => { setPlaying(false); step(); });
  $('play').addEventListener('click', () => setPlaying(!playing));
  $('reset').addEventListener('click', () => loadScene(true));
  $('export-obj').addEventListener('click', () => {
    try {
      const text = session ? session.exportObj() : mesh?.toObj();
      if (text) download(`${config.scene}.obj`, text, 'text/plain');
    } catch (e) { showError(e); }
  });
  $('screenshot').addEventListener('click', async () => {
    try { download(`${config.scene}@2x.png`, await snapshotPng(2)); } catch (e) { showStatus(`${viewer.backend} · ${e.message ?? e}`, true); }
  });
  writeHash(config);
  wireInput();
  loadScene(true);
  requestAnimationFrame(frame);
}

main();
