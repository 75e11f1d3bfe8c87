// Presentation mode: the current panels as glass in metal frames, with sun shadows, a damped
// orbit, full screen and a 2x PNG. Rendering and geometry are wasm's (`Presenter`); this file
// wires events and the frame loop.
import { forcedWebgl2, wasm } from './wasm.js';
import { download } from './download.js';

let presenter = null;
let panel, canvas, statusEl, frameEl, offsetBox;
let open = false;
let dirty = true;
let getMesh = () => null;
let demo = null;         // MeshData of the 10k-panel demo, when shown

const el = (tag, attrs = {}, text) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
};

function status(text, isError = false) {
  statusEl.textContent = text;
  statusEl.classList.toggle('error', isError);
}

function show(mesh) {
  if (!presenter || !mesh) return;
  try {
    const info = presenter.setMesh(mesh, offsetBox.checked);
    statusEl.dataset.panels = String(info.panels);
    status(`${presenter.backend} · ${info.panels} panels · ${info.beams} beams${info.offsetError ? ` · ${info.offsetError}` : ''}`, !!info.offsetError);
    dirty = true;
  } catch (e) { status(String(e.message ?? e), true); }
}

// Drawing-buffer size: CSS size x devicePixelRatio, with the ratio capped at 2 and the buffer
// at about 4 megapixels (a 3840 x 2160 CSS full screen at dpr 2 would be 33 MP: 8x the work for
// no visible gain), so the fill rate per frame stays bounded whatever the display.
const MAX_DPR = 2;
const MAX_PIXELS = 2560 * 1600;
function resize() {
  const cw = Math.max(1, canvas.clientWidth), ch = Math.max(1, canvas.clientHeight);
  const dpr = Math.min(window.devicePixelRatio || 1, MAX_DPR, Math.sqrt(MAX_PIXELS / (cw * ch)));
  const w = Math.max(1, Math.round(cw * dpr));
  const h = Math.max(1, Math.round(ch * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; presenter.resize(w, h); dirty = true; }
}

// Frame-time readout over the last FRAME_WINDOW drawn frames: the interval between consecutive
// drawn animation frames (a pause resets it) and the CPU time of the `render()` call (encoding
// and submitting; the GPU works asynchronously). On the canvas as `data-frame-ms`,
// `data-fps` and `data-render-ms`, and as text in the bar.
const FRAME_WINDOW = 30;
const intervals = [], renderMs = [];
let lastDrawn = 0;
function recordFrame(t, ms, drewLast) {
  const push = (a, v) => { a.push(v); if (a.length > FRAME_WINDOW) a.shift(); };
  if (drewLast) push(intervals, t - lastDrawn);
  push(renderMs, ms);
  lastDrawn = t;
  const mean = (a) => a.reduce((x, y) => x + y, 0) / a.length;
  canvas.dataset.renderMs = mean(renderMs).toFixed(2);
  if (intervals.length) {
    const f = mean(intervals);
    canvas.dataset.frameMs = f.toFixed(2);
    canvas.dataset.fps = (1000 / f).toFixed(1);
    frameEl.textContent = `${f.toFixed(1)} ms/frame · ${(1000 / f).toFixed(0)} fps · render() ${mean(renderMs).toFixed(2)} ms`;
  }
}

let last = 0;
let drewLast = false;
let autoOrbit = null;    // { left, resolve }: orbitFrames() turning the view one step a frame
function frame(t) {
  if (!open) return;
  const dt = last ? t - last : 16;
  last = t;
  resize();
  presenter.poll();
  if (autoOrbit) { presenter.orbit(0.01, 0, 16); presenter.stop(); dirty = true; }
  if (presenter.tick(dt)) dirty = true;
  if (dirty) {
    dirty = false;
    const t0 = performance.now();
    try { presenter.render(); } catch (e) { status(String(e.message ?? e), true); }
    recordFrame(t, performance.now() - t0, drewLast);
    drewLast = true;
    statusEl.dataset.rendered = 'true';
    if (autoOrbit && --autoOrbit.left <= 0) { autoOrbit.resolve(); autoOrbit = null; }
  } else drewLast = false;
  requestAnimationFrame(frame);
}

async function openPresentation() {
  panel.hidden = false;
  open = true;
  if (!presenter) {
    try {
      canvas.width = Math.max(1, canvas.clientWidth);
      canvas.height = Math.max(1, canvas.clientHeight);
      presenter = await wasm.Presenter.create(canvas, forcedWebgl2);
    } catch (e) { status(`Cannot start presentation: ${e.message ?? e}`, true); return; }
  }
  show(demo ?? getMesh());
  last = 0;
  drewLast = false;
  requestAnimationFrame(frame);
}

function closePresentation() {
  open = false;
  panel.hidden = true;
  if (document.fullscreenElement) document.exitFullscreen().catch(() => {});
}

function wireOrbit() {
  const pointers = new Map();
  let lastMove = 0;
  canvas.addEventListener('pointerdown', (e) => { canvas.setPointerCapture(e.pointerId); pointers.set(e.pointerId, e); presenter?.stop(); lastMove = performance.now(); });
  canvas.addEventListener('pointermove', (e) => {
    const prev = pointers.get(e.pointerId);
    if (!prev || !presenter) return;
    pointers.set(e.pointerId, e);
    const now = performance.now();
    presenter.orbit((e.clientX - prev.clientX) * 0.008, (e.clientY - prev.clientY) * 0.008, now - lastMove);
    lastMove = now;
    dirty = true;
  });
  const up = (e) => pointers.delete(e.pointerId);
  canvas.addEventListener('pointerup', up);
  canvas.addEventListener('pointercancel', up);
  canvas.addEventListener('wheel', (e) => { e.preventDefault(); presenter?.zoom(Math.exp(e.deltaY * 0.001)); dirty = true; }, { passive: false });
}

async function snapshotPng(scale) {
  const image = await presenter.snapshot(scale);
  const c = new OffscreenCanvas(image.width, image.height);
  c.getContext('2d').putImageData(image, 0, 0);
  return c.convertToBlob({ type: 'image/png' });
}

/** Adds the Present button and the presentation overlay; `currentMesh()` gives the MeshData. */
export function initPresent(currentMesh) {
  getMesh = currentMesh;
  panel = el('section', { class: 'present', 'data-testid': 'present-panel', 'aria-label': 'Presentation', hidden: '' });
  canvas = el('canvas', { 'data-testid': 'present-canvas', 'aria-label': 'Presentation view: drag to orbit' });
  offsetBox = el('input', { type: 'checkbox', 'data-testid': 'present-offset' });
  const offsetLabel = el('label', {}, ' offset layer');
  offsetLabel.prepend(offsetBox);
  const demoBtn = el('button', { type: 'button', 'data-testid': 'present-demo', title: 'A torus of 10 000 panels' }, '10k panels');
  const pngBtn = el('button', { type: 'button', 'data-testid': 'present-png' }, 'PNG ×2');
  const fsBtn = el('button', { type: 'button', 'data-testid': 'present-fullscreen' }, 'Full screen');
  const closeBtn = el('button', { type: 'button', 'data-testid': 'present-close' }, 'Close');
  statusEl = el('p', { 'data-testid': 'present-status', role: 'status', class: 'present-status' });
  frameEl = el('p', { 'data-testid': 'present-frame', class: 'present-status' });
  const bar = el('div', { class: 'present-bar' });
  bar.append(offsetLabel, demoBtn, pngBtn, fsBtn, closeBtn, statusEl, frameEl);
  panel.append(canvas, bar);
  document.body.append(panel);
  const toggle = el('button', { type: 'button', 'data-testid': 'present' }, 'Present');
  toggle.addEventListener('click', openPresentation);
  document.querySelector('header .buttons')?.append(toggle);
  closeBtn.addEventListener('click', closePresentation);
  offsetBox.addEventListener('change', () => show(demo ?? getMesh()));
  demoBtn.addEventListener('click', () => {
    demo?.free();
    demo = wasm.torusPanels(10000);
    show(demo);
  });
  fsBtn.addEventListener('click', () => {
    (document.fullscreenElement ? document.exitFullscreen() : panel.requestFullscreen())
      .catch((e) => status(`full screen refused: ${e.message ?? e}`, true));
  });
  pngBtn.addEventListener('click', async () => {
    try {
      download('dupin-presentation@2x.png', await snapshotPng(2));
    } catch (e) { status(String(e.message ?? e), true); }
  });
  document.addEventListener('keydown', (e) => { if (open && e.key === 'Escape' && !document.fullscreenElement) closePresentation(); });
  wireOrbit();
  // For tests and benchmarks: pixels, and the mean frame interval over `frames` orbiting frames.
  window.dupinPresent = {
    snapshotDataUrl: async (scale = 1) => {
      const blob = await snapshotPng(scale);
      return new Promise((resolve) => { const r = new FileReader(); r.onload = () => resolve(r.result); r.readAsDataURL(blob); });
    },
    size: () => [canvas.width, canvas.height],
    // Orbits one step per animation frame through the page's own frame loop for `frames`
    // drawn frames, then returns the readout over them (mean interval between frames, mean CPU
    // time of `render()`), as the canvas's data attributes show it.
    orbitFrames: async (frames) => {
      intervals.length = 0;
      renderMs.length = 0;
      await new Promise((resolve) => { autoOrbit = { left: frames, resolve }; });
      return {
        frames,
        meanIntervalMs: Number(canvas.dataset.frameMs),
        meanRenderCallMs: Number(canvas.dataset.renderMs),
        fps: Number(canvas.dataset.fps),
        size: [canvas.width, canvas.height],
      };
    },
  };
}
