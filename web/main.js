// Dupin configurator: a thin shell. Geometry lives in Rust (../crates/dupin-web): the solver's
// `Session` runs in a module worker (worker.js), the wgpu `Viewer` draws here. This file wires
// DOM events, the URL hash and the frame loop; the pieces are small modules:
//   config.js (configuration <-> hash), controls.js (picker and fields), metrics.js (panel,
//   histogram, legend), solver.js (worker client). Other tabs plug in through `window.dupin`.
import { forcedWebgl2, loadWasm, openView, workerUrl } from './wasm.js';
import { FREE, IMPORTED, defaults, readHash, schema, sessionConfig, useSchema, writeHash } from './config.js';
import { buildFields, clearFieldErrors, fillScenePicker, showFieldError } from './controls.js';
import { drawHistogram, drawLegend, legendCaption, showMetrics, showProgress } from './metrics.js';
import { SettingsHistory } from './undo.js';
import { download } from './download.js';
import { BoxSelection } from './box-select.js';
import { ControlNetOverlay } from './control-net.js';
import { presentationFile } from './share.js';
import { Solver } from './solver.js';
import { ShownArrays } from './shown-arrays.js';
import { initTeach, showPick } from './teach.js';
import { initHexd2d } from './hexd2d.js';
import { initPresent } from './present.js';
import { read3dm, write3dm } from './rhino.js';
import { loadDesign, saveDesign } from './design-store.js';

const $ = (id) => document.querySelector(`[data-testid="${id}"]`);
const statusEl = $('status');
const metricsEl = $('metrics');
const canvas = $('canvas');
const fieldsBox = document.getElementById('params');

// The wasm module's exports (wasm.js picks the WebGPU or the WebGL2 build), set by main().
let MeshData, Viewer, colorLegend, dupinVersion, freeDefaults, pageSchema, sceneDescription, sceneNames, surfaceCatalog, torusMesh;
let TORUS = null;         // the torus preview's parameters { key: { label, value } } (pageSchema)

let viewer = null;
let solver = null;
let mesh = null;          // MeshData on screen
const shownArrays = new ShownArrays(); // the worker's mesh arrays, its states' additions appended
let config = null;        // what is on screen (last configuration that loaded; defaults once loaded)
let running = false;      // a stepped scene or free configuration is loaded in the worker
let playing = false;
let done = true;
let dirty = true;
let lastFaces = 0;
let lastPhase = '';
let userMoved = false;
let pendingCamera = null; // camera from a restored URL, applied with the first mesh
let ctx = null;           // { scenes, catalog, defaults }
let lastMetrics = null;   // metrics on screen (redrawn when the panel edge changes)
let lastLayers = null;    // offset and beam layers on show: { unavailable, info } (showLayers)
let pickedPoint = null;   // 3D point of the vertex clicked for the teaching inset (marked)
const marker = document.createElement('div');
let selection = null;     // box-selected vertices of a panel mesh in edit mode (box-select.js)
let net = null;           // an opened NURBS surface's control net, dragged in edit mode (control-net.js)
const stepLog = [];      // per-step { phase, faces, ms } for benchmarks (window.dupin.stepLog)
let settled = false;      // something was shown or reported (the first frame may count as ready)
let opened = null;        // the design the user opened: { name, bytes } (never leaves the page)
// A first visit (no hash) opens on a finished, attractive result rather than an empty scene, with
// a line saying what Dupin does; any choice of the user's own ends the welcome.
const OPENING = { scene: 'cyclide-architecture', what: 'the P-Hex paper\'s Fig. 1, 3 200 planar hexagons on a Dupin cyclide' };
let welcome = false;
const undoStack = new SettingsHistory();
let runT0 = 0;            // when the run on show was loaded (its progress estimate starts there)

function showStatus(text, isError = false) {
  statusEl.textContent = text;
  statusEl.classList.toggle('error', isError);
}

// Only when the hash changed: replaceState per worker message was main-thread work for nothing.
/** One line for people about what is on screen and what to press. */
function describe(c) {
  $('scene-description').classList.toggle('welcome', welcome && c.scene === OPENING.scene);
  const text = welcome && c.scene === OPENING.scene
    ? `Dupin turns freeform designs into exactly planar panels for flat glass or metal. This is ${OPENING.what}: drag to orbit it, Reset then Play to watch it computed, or pick a scene or open your own design.`
    : c.scene === 'torus'
    ? 'Dupin makes freeform designs buildable from flat panels. Pick a scene from the papers and press Play, or open your own design.'
    : c.scene === FREE
      ? 'Any library surface panelled by P-Hex: choose the surface, method, panel size and weights, then press Play.'
      : c.scene === IMPORTED
        ? 'Your design: a surface is panelled by P-Hex, panels are made planar keeping the design; press Play, then export.'
        : `${sceneDescription(c.scene) ?? ''} Press Play to run it, Step to watch it step by step.`;
  setProp($('scene-description'), 'textContent', text);
}

function syncHash() {
  describe(config);
  const h = writeHash(config);
  if (h !== location.hash) history.replaceState(null, '', h);
  undoStack.note(h);
  updateUndoButtons();
}

function updateUndoButtons() {
  setProp($('undo'), 'disabled', !undoStack.past.length);
  setProp($('redo'), 'disabled', !undoStack.future.length);
}

/** Undo (or redo) the last change of a setting: the page restores that setting's hash. */
function undoRedo(redo) {
  const h = redo ? undoStack.redo() : undoStack.undo();
  updateUndoButtons();
  if (!h) return;
  welcome = false;
  history.replaceState(null, '', h);
  restore(h);
}

function showMesh(next, reframe) {
  viewer.setMesh(next, reframe);
  mesh?.free();
  mesh = next;
  settled = true;
  if (pendingCamera) {
    viewer.setCamera(pendingCamera);
    pendingCamera = null;
    userMoved = true;
  }
  dirty = true;
}

// Writes only changed properties (each write invalidates style, and layout under the cursor
// makes Chromium hit-test a synthetic mouse move).
function setProp(el, key, value) { if (el[key] !== value) el[key] = value; }

function updateButtons() {
  // A value the core refused stays in its field, in red, while the run keeps the previous
  // settings: Step and Play wait until it is fixed rather than run what the field does not show.
  const refused = fieldsBox.querySelector('input.invalid');
  const why = refused ? `fix the value in red first (${refused.dataset.testid}): the run on screen still uses the previous one` : '';
  setProp($('step'), 'disabled', !running || done || !!refused);
  setProp($('play'), 'disabled', !running || done || (!!refused && !playing));
  setProp($('step'), 'title', why);
  setProp($('play'), 'title', why);
  setProp($('reset'), 'disabled', !running);
  setProp($('stop'), 'disabled', !candidate && (!running || done));
  setProp($('play'), 'textContent', playing ? 'Pause' : 'Play');
  for (const id of ['export-json', 'export-svg', 'export-dxf', 'export-csv', 'export-glb', 'export-3dm', 'share-presentation']) setProp($(id), 'disabled', !running);
}

// ---- loading a configuration -----------------------------------------------------------------
/** Shows configuration `next`; `field` names the input that changed (its errors go there). */
function load(next, { reframe = true, field = null, rebuild = false } = {}) {
  setMarker(null);
  dragPending = false; // a new run supersedes any drag
  // Another run (a scene, a setting, undo): its vertices are not the selected ones.
  selection?.clear();
  if (next.scene === 'torus') {
    try {
      const m = torusMesh(next.params.R, next.params.r, 96, 48);
      solver.post('pause');
      solver.gen += 1; // drop anything the worker still sends for the previous run
      running = false; playing = false; done = true;
      panelNext = null;
      meshNext = null;
      config = next;
      showMesh(m, reframe);
      lastMetrics = { phase: 'done', preview: true, iteration: 0, faces: m.triangleCount, vertices: m.vertexCount, maxPlanarity: 0 };
      showMetrics(metricsEl, lastMetrics, config);
      showProgress($('progress'), lastMetrics, { show: false, recentMs: [] });
      drawHistogram($('histogram'), {});
      showLayers({ unavailable: 'the torus preview is a smooth surface: offset and support beams need a conical scene (conical-station)', info: null });
      if (field) showFieldError(fieldsBox, field, '');
      showStatus(viewer.backend);
      syncHash();
    } catch (e) {
      reportError(e.message ?? String(e), field);
    }
    updateButtons();
    return;
  }
  if (next.scene === IMPORTED && !opened) {
    // A link or reload of an imported design: the file stays on the user's machine.
    solver.post('pause');
    solver.gen += 1;
    running = false; playing = false; done = true;
    config = next;
    settled = true;
    showStatus(`${viewer.backend} · this page showed an imported design; its file is not here (files never leave your browser): open it again with “Open design” or drop it on the page`, true);
    updateButtons();
    return;
  }
  lastFaces = 0;
  lastPhase = '';
  runT0 = performance.now();
  userMoved = !!pendingCamera;
  candidate = { config: next, field, reframe, rebuild };
  const file = next.scene === IMPORTED ? { name: opened.name, bytes: opened.bytes } : null;
  const cfg = sessionConfig(next);
  // A .3dm's own unit, unless the user picked one.
  if (file && opened.unit && !cfg.unit) cfg.unit = opened.unit;
  solver.load(cfg, { steps: next.steps, mode: next.color, field, layers: next.layers, file, edits: next.edits });
  if (file) watchRead(candidate, opened.name);
  updateButtons();
}

/** While the worker reads (and fits) an opened design: after 0.5 s the status counts the
 * seconds and says that Stop cancels (the read cannot report finer progress from inside one
 * wasm call; Stop replaces the worker and the previous run comes back). */
function watchRead(pending, name) {
  const t0 = performance.now();
  const tick = () => {
    if (candidate !== pending) return;
    const s = (performance.now() - t0) / 1000;
    if (s >= 0.5) showStatus(`${viewer.backend} · reading ${name}… ${s.toFixed(0)} s (Stop cancels)`);
    setTimeout(tick, 250);
  };
  setTimeout(tick, 500);
}

/** Opens a design file (file input or drop): shown as `imported: NAME` once the worker has read
 * it; a file it cannot read leaves the current run on screen and says why. */
async function openDesign(file) {
  if (!file) return;
  welcome = false;
  let bytes;
  try {
    bytes = new Uint8Array(await file.arrayBuffer());
  } catch (e) {
    showStatus(`${viewer.backend} · ${file.name}: the browser could not read the file (${e.message ?? e})`, true);
    return;
  }
  let unit = null;
  let note = '';
  if (/\.3dm$/i.test(file.name)) {
    // Rhino's format, read by rhino3dm into the NURBS JSON or OBJ the solver reads.
    showStatus(`${viewer.backend} · reading ${file.name} with rhino3dm…`);
    try {
      const design = await read3dm(bytes, file.name);
      bytes = new TextEncoder().encode(design.text);
      unit = design.unit;
      note = [`${design.kind}: ${design.name}`, design.note].filter(Boolean).join('; ');
    } catch (e) {
      showStatus(`${viewer.backend} · ${file.name}: ${e.message ?? e}`, true);
      return;
    }
  }
  previousOpened = opened;
  opened = { name: file.name, bytes, unit, note };
  const next = defaults();
  Object.assign(next, { scene: IMPORTED, color: config.color, panelEdge: config.panelEdge, layers: config.layers, backend: config.backend });
  next.imported.name = file.name;
  showStatus(`${viewer.backend} · reading ${file.name}…`);
  load(next, { reframe: true, field: 'import-file', rebuild: true });
}
let previousOpened = null;
let candidate = null; // configuration sent to the worker, not yet confirmed

function onState(s) {
  const t0 = performance.now();
  try { applyState(s); } finally { noteTask('state', t0); }
}

// Main-thread work per worker message and per frame over 16 ms (window.dupin.slowTasks), to
// find what a long task was.
const slowTasks = [];
function noteTask(what, t0, parts = null) {
  const ms = performance.now() - t0;
  if (ms > 16 && slowTasks.length < 1000) slowTasks.push({ what, ms: Math.round(ms), faces: lastFaces, ...(parts && { parts }) });
}

function applyState(s) {
  const t0main = performance.now();
  if (candidate) {
    config = candidate.config;
    const design = s.metrics.design;
    if (config.scene === IMPORTED && design) {
      const read = { as: design.importAs, unit: design.unit };
      // The import selects show what the worker made of the file.
      if (read.as !== config.imported.read?.as || read.unit !== config.imported.read?.unit) candidate.rebuild = true;
      config.imported.read = read;
    }
    if (candidate.rebuild) {
      fillScenePicker($('scene-select'), ctx.scenes, opened?.name);
      $('scene-select').value = config.scene;
      rebuildFields();
    }
    if (candidate.field) showFieldError(fieldsBox, candidate.field, '');
    // An opened design the worker has read is kept for a reload (design-store.js).
    if (candidate.field === 'import-file' && opened) saveDesign(opened);
    candidate = null;
    running = true;
    showStatus(notice ? `${viewer.backend} · ${notice.text}` : viewer.backend, !!notice?.isError);
    notice = null;
    recovering = false;
  }
  const m = s.metrics;
  m.steps = s.steps;
  config.steps = s.steps;
  done = s.done;
  playing = s.playing;
  // Frame the growing mesh at its first step and once more when its last layer is in, unless
  // the user has taken the camera.
  const grown = lastPhase === 'triangulation' && m.phase !== 'triangulation';
  const arrays = shownArrays.apply(s.mesh);
  if (arrays) scheduleMesh(arrays, lastFaces === 0 ? !userMoved : grown && !userMoved, m.faces);
  else solver.post('resync'); // a missed state: the worker sends the whole mesh next
  if (s.layers) showLayers(s.layers);
  lastFaces = m.faces;
  lastPhase = m.phase;
  lastMetrics = m;
  const warned = statusEl.dataset.warning === 'true';
  statusEl.dataset.warning = String(m.phase === 'warning');
  if (m.phase === 'warning') showStatus(`${viewer.backend} · NOT done: ${m.reason}`, true);
  // A run that starts again (a dragged control point, a drag after a warning) takes the
  // warning down.
  else if (m.design && (s.steps <= 1 || warned)) showStatus(`${viewer.backend} · ${designLine(m.design)}`);
  else if (warned) showStatus(viewer.backend);
  if (s.dragSeq === dragSeq && ['done', 'warning'].includes(m.phase)) dragPending = false;
  const entry = { dragSeq: s.dragSeq, phase: m.phase, layer: m.layer, iteration: m.iteration, faces: m.faces, maxPlanarity: m.maxPlanarity, steps: s.steps, ms: m.ms, timing: m.timing, mainMs: performance.now() - t0main, panelMs: null, at: performance.now() };
  stepLog.push(entry);
  if (stepLog.length > 5000) stepLog.shift();
  schedulePanel(m, entry);
  net.set(m.design?.controlNet ?? null, m.viewOrigin);
  if (netDrag) net.place(netDrag.index, netDrag.sent ?? netDrag.point);
  net.show(editMode);
  const canEdit = editable(m) || net.available;
  setProp($('edit-vertices'), 'hidden', !canEdit);
  setProp($('edit-vertices'), 'textContent', net.available ? 'Drag control points' : 'Drag vertices');
  if (!canEdit && editMode) setEditMode(false);
  dragStateArrived(m.phase);
  netStateArrived(s.dragSeq, m.phase);
  if (playing) requestAnimationFrame(() => solver.post('ack'));
}

// Meshes to the GPU: at once when stepped, paused or done; while playing at most one per
// min(200 ms, faces / 50 ms), latest wins (a reframe asked for by a skipped state is kept). A 10k
// mesh upload and the frame after it waited 30-200 ms on the GPU process (SwiftShader) on the
// loaded box, and skipped meshes also leave the GPU process's cores to the worker.
let meshNext = null; // { arrays, reframe }: the mesh the next upload shows
let meshTimer = 0;
let meshAt = -Infinity;
function scheduleMesh(arrays, reframe, faces) {
  meshNext = { arrays, reframe: reframe || (meshNext?.reframe ?? false) };
  const wait = playing && !done ? Math.max(0, meshAt + Math.min(200, faces / 50) - performance.now()) : 0;
  if (wait > 0) {
    if (!meshTimer) meshTimer = setTimeout(uploadMesh, wait);
    return;
  }
  clearTimeout(meshTimer);
  uploadMesh();
}

function uploadMesh() {
  meshTimer = 0;
  if (!meshNext) return; // a torus preview replaced the run meanwhile
  const { arrays: a, reframe } = meshNext;
  meshNext = null;
  meshAt = performance.now();
  const parts = {};
  try {
    const m = MeshData.fromArrays(a.positions, a.normals, a.indices, a.colors, a.edges);
    m.setPanels(a.panelPositions, a.panelFaces, a.viewOrigin);
    parts.copy = performance.now() - meshAt;
    showMesh(m, reframe);
    parts.gpu = performance.now() - meshAt - parts.copy;
  } catch (e) {
    showStatus(`${viewer.backend} · ${e.message ?? e}`, true);
  }
  noteTask('mesh', meshAt, parts);
}

// The panel (contract data attributes, text, histogram), URL and buttons are written together in
// a task of their own: with the mesh upload they made 50-75 ms tasks on the loaded box (the
// page's long-task budget is 50 ms). Coalesced, latest state wins; while playing at most every
// PANEL_MS (a 10k run posts ~14 states/s, more than anyone reads, and each update costs style,
// layout and paint); a step, a pause and the final state are written in the next task.
const PANEL_MS = 200;
let panelNext = null; // { m, entry }: the state the panel task will show
let panelTimer = 0;
let panelAt = -Infinity;
function schedulePanel(m, entry) {
  panelNext = { m, entry };
  const wait = playing && !done ? Math.max(0, panelAt + PANEL_MS - performance.now()) : 0;
  if (panelTimer && wait > 0) return; // the pending update will show the latest state
  clearTimeout(panelTimer);
  panelTimer = setTimeout(showPanel, wait);
}

function showPanel() {
  panelTimer = 0;
  if (!panelNext) return; // a torus preview replaced the run meanwhile
  const t1 = performance.now();
  panelAt = t1;
  const { m, entry } = panelNext;
  panelNext = null;
  showMetrics(metricsEl, m, config);
  showLegend();
  // The bar: after a second of playing (short runs would only flash it), or while stepping.
  const recentMs = stepLog.slice(-5).filter((e) => e.at >= runT0 && e.phase === m.phase && Number.isFinite(e.ms)).map((e) => e.ms);
  showProgress($('progress'), m, { show: !done && !m.preview && (playing ? performance.now() - runT0 > 1000 : (m.steps ?? 0) > 1), recentMs });
  const t2 = performance.now();
  drawHistogram($('histogram'), m);
  const t3 = performance.now();
  // history.replaceState took 10-80 ms of wall time per call on the loaded box (it waits on the
  // browser process; entry.panelParts.hash): the URL follows a playing run only when it stops
  // (done, a step, a pause: see the play button). While a control point is dragged the states
  // are of a net the URL does not have yet (the release writes it): a follow that is done
  // mid-drag must not write its steps under the net before the drag, Undo's entry.
  if ((!playing || done) && !netDrag) syncHash();
  const t4 = performance.now();
  updateButtons();
  entry.panelMs = performance.now() - t1;
  entry.panelParts = { metrics: t2 - t1, histogram: t3 - t2, hash: t4 - t3, buttons: performance.now() - t4 };
  noteTask('panel', t1);
}

// ---- offset and support layers (conical scenes): computed in Rust, toggled here -----------------
/** Enables the layer toggles where the run has an offset, else shows why not; `info` is
 * Session.layerInfo (measures of the layers on show). */
function showLayers({ unavailable, info }) {
  lastLayers = { unavailable, info };
  // Called per worker state: writes only what changed (see setProp).
  for (const id of ['toggle-offset', 'toggle-support', 'offset-distance']) setProp($(id), 'disabled', !!unavailable);
  setProp($('offset-reason'), 'textContent', unavailable ?? '');
  const li = $('layer-info');
  setProp(li, 'textContent', info
    ? `offset: ${info.offsetFaces} faces, planarity ${info.offsetPlanarity.toExponential(1)} · ${info.beams} beams, planarity ${info.beamPlanarity.toExponential(1)}`
    : '');
  if (info) for (const [k, v] of Object.entries({ beams: info.beams, beamPlanarity: info.beamPlanarity, offsetPlanarity: info.offsetPlanarity })) setProp(li.dataset, k, String(v));
  else for (const k of ['beams', 'beamPlanarity', 'offsetPlanarity']) delete li.dataset[k];
}

function showLayerError(message) {
  $('offset-distance-error').textContent = message;
  $('offset-distance').classList.toggle('invalid', message !== '');
}

function setLayers(patch) {
  config.layers = { ...config.layers, ...patch };
  showLayerError('');
  if (running) solver.post('layers', { layers: config.layers });
  syncHash();
}

function reportError(message, field) {
  settled = true;
  dirty = true; // a refused first configuration still draws its (empty) frame: the page is ready
  if (field === 'offset-distance') { showLayerError(message); return; }
  if (!(field && showFieldError(fieldsBox, field, message))) showStatus(`${viewer.backend} · ${message}`, true);
}

// ---- stopping and recovering -----------------------------------------------------------------
// Stop, a trap or an out-of-memory in the worker: a fresh worker, and the last state the page
// showed (the confirmed configuration at its step count) replayed into it. A fault during that
// replay is not retried (it would fault again): the message stays and Reset or another scene
// start over.
let notice = null;     // { text, isError } shown in the status once the replayed state arrives
let recovering = false;

async function restartSolver(message, isError) {
  playing = false;
  running = false; // Step, Play and Stop wait for the restored state
  candidate = null;
  updateButtons();
  showStatus(`${viewer.backend} · ${message}`, isError);
  await solver.restart();
  if (config.scene === 'torus') return;
  notice = { text: message, isError };
  recovering = true;
  load(config, { reframe: false });
}

function onFault(message) {
  if (recovering) {
    recovering = false;
    running = false;
    notice = null;
    updateButtons();
    solver.restart();
    showStatus(`${viewer.backend} · the solver failed again while restoring (${message}); press Reset or pick another scene`, true);
    return;
  }
  restartSolver(`the solver failed (${message}) and was restarted at step ${config.steps}`, true);
}

function stop() {
  if (candidate) {
    // Cancel a load (a long read or fit): the previous run comes back.
    if (candidate.field === 'import-file') opened = previousOpened;
    restartSolver(config.scene === 'torus' ? 'cancelled' : `cancelled; back at step ${config.steps}`, false);
    return;
  }
  if (!running || done) return;
  restartSolver(`stopped; back at step ${config.steps}`, false);
}

/** `imported: NAME · surface · 20.00 × 15.00 × 3.40 m (unit m) · surface fitted within 0.11 mm
 * · read in 0.39 s, fitted in 1.2 s`. */
function designLine(d) {
  const dims = d.dimensionsM.map((x) => x.toFixed(2)).join(' × ');
  const fit = d.fitMaxDistanceM === undefined ? '' : ` · surface fitted within ${(d.fitMaxDistanceM * 1000).toFixed(2)} mm`;
  const note = opened?.note ? ` · ${opened.note}` : '';
  const secs = (s) => (s < 10 ? s.toFixed(2) : s.toFixed(0));
  const took = ` · read in ${secs(d.readSeconds)} s${d.fitSeconds === undefined ? '' : `, fitted in ${secs(d.fitSeconds)} s`}`;
  return `imported: ${d.name} · ${d.importAs} · ${dims} m (unit ${d.unit})${fit}${note}${took}`;
}

function onError(e) {
  playing = false;
  if (e.load && candidate?.field === 'import-file') opened = previousOpened; // the old run stays
  if (e.load) {
    const field = candidate?.field ?? e.field;
    candidate = null;
    reportError(e.message, field);
  } else {
    reportError(e.message, e.field);
  }
  updateButtons();
}

// ---- downloads (download.js) -------------------------------------------------------------------
const EXPORT_TYPES = { obj: 'text/plain', json: 'application/json', svg: 'image/svg+xml', dxf: 'application/dxf', csv: 'text/csv', glb: 'model/gltf-binary' };
function onExport(m) {
  if (m.kind === 'share') {
    const name = exportName();
    // The offset and beam figures of the layers on show (a conical scene's), for the certificate.
    const layers = config.layers.offset && lastLayers?.info ? lastLayers : null;
    presentationFile(m.text, Array.from(viewer.camera()), {
      layers, panelEdge: config.panelEdge, title: name, version: dupinVersion(),
    }).then((html) => download(`${name}-presentation.html`, html, 'text/html'))
      .catch((e) => showStatus(`${viewer.backend} · presentation not written: ${e.message ?? e}`, true));
    return;
  }
  if (m.kind === '3dm') {
    // The panels from the solver, written by rhino3dm in its worker.
    const name = exportName();
    write3dm(m.text).then(({ bytes, degenerate }) => {
      download(`${name}.3dm`, bytes, 'application/octet-stream');
      if (degenerate) showStatus(`${viewer.backend} · ${name}.3dm: ${degenerate} degenerate panel(s) written as outlines only`, true);
    })
      .catch((e) => showStatus(`${viewer.backend} · 3dm export failed: ${e.message ?? e}`, true));
    return;
  }
  download(`${exportName()}.${m.kind}`, m.text, EXPORT_TYPES[m.kind]);
}

function exportName() {
  return config.scene === FREE ? `free-${config.free.surface}`
    : config.scene === IMPORTED ? (opened?.name ?? 'design').replace(/\.[^.]*$/, '') : config.scene;
}

/** Renders the view at `scale` x the canvas size on the GPU and returns a PNG blob. */
async function snapshotPng(scale = 1) {
  const image = await viewer.snapshot(scale);
  const c = new OffscreenCanvas(image.width, image.height);
  c.getContext('2d').putImageData(image, 0, 0);
  return c.convertToBlob({ type: 'image/png' });
}

// For tests and scripting: pixels as the page draws them (headless Chromium composites no WebGPU
// canvas into its own screenshots), and hooks for other tabs.
window.dupin = {
  snapshotDataUrl: async (scale = 1) => {
    const blob = await snapshotPng(scale);
    return new Promise((resolve) => { const r = new FileReader(); r.onload = () => resolve(r.result); r.readAsDataURL(blob); });
  },
  get viewer() { return viewer; },
  get config() { return config; },
  requestRedraw: () => { dirty = true; },
  /** Clicks the 3D view at canvas pixel (x, y) as a user would (for scripts). */
  pickAt: (x, y) => pickAt(x, y),
  get picked() { return pickedPoint; },
  stepLog,
  slowTasks,
  /** The number of the last drag or reshape sent, and whether its run is still to finish. */
  get dragSeq() { return dragSeq; },
  get dragPending() { return dragPending; },
  /** The worker's mesh arrays as the page holds them (shown-arrays.js), and a request for the
   * whole mesh in the next state. */
  get shownArrays() { return shownArrays; },
  resync: () => solver.post('resync'),
  /** Makes the solver worker trap (`'trap'`) or run out of memory (`'oom'`), to test recovery. */
  fault: (kind) => solver.post('fault', { kind }),
};

// ---- orbit: mouse drag, wheel, touch (one finger orbits, two pinch) ---------------------------
function cameraMoved() {
  userMoved = true;
  dirty = true;
  clearTimeout(cameraMoved.timer);
  cameraMoved.timer = setTimeout(() => { config.camera = Array.from(viewer.camera()); syncHash(); }, 150);
}

// ---- picking a vertex for the teaching inset: a click (no drag) on the 3D view --------------
// JS only turns the click into normalised device coordinates; the view ray (Viewer.pickRay) and
// the vertex and its star (Session.pickVertex, in the worker) are computed in Rust.
// On an opened panel mesh a click anchors (or releases) the vertex under it instead.
function pickAt(x, y) {
  const panels = config.scene === IMPORTED && (config.imported.as ?? config.imported.read?.as) === 'panels';
  if (!running) {
    if (!panels) showPick(null, 'Vertex picking needs a P-Hex scene or free configuration (load one, then click the mesh).');
    return;
  }
  const nx = (x / canvas.clientWidth) * 2 - 1, ny = 1 - (y / canvas.clientHeight) * 2;
  try {
    const r = viewer.pickRay(nx, ny);
    solver.post('pick', { origin: Array.from(r.slice(0, 3)), direction: Array.from(r.slice(3, 6)), panels });
  } catch (e) {
    if (panels) reportError(e.message ?? String(e), 'import-anchors');
    else showPick(null, e.message ?? String(e));
  }
}

function onPick(m) {
  if (m.drag) { dragPicked(m); return; }
  if (m.panels) {
    if (m.error) { reportError(m.error, 'import-anchors'); return; }
    if (!m.pick) return; // a click beside the mesh
    const next = structuredClone(config);
    const a = next.imported.anchors;
    const k = a.indexOf(m.pick.vertex);
    if (k >= 0) a.splice(k, 1); else a.push(m.pick.vertex);
    a.sort((x, y) => x - y);
    next.steps = 1;
    next.edits = [];
    // The run restarts with the new anchors; fields show the count once it is accepted.
    load(next, { reframe: false, field: 'import-anchors', rebuild: true });
    return;
  }
  const pick = showPick(m.pick, m.error);
  setMarker(pick ? pick.point : null);
}

function setMarker(point) {
  pickedPoint = point;
  marker.dataset.vertex = point ? 'set' : '';
  placeMarker();
}

function placeMarker() {
  const p = pickedPoint && viewer.project(pickedPoint[0], pickedPoint[1], pickedPoint[2]);
  marker.hidden = !p;
  if (!p) return;
  marker.style.left = `${canvas.offsetLeft + (p[0] + 1) * 0.5 * canvas.clientWidth}px`;
  marker.style.top = `${canvas.offsetTop + (1 - p[1]) * 0.5 * canvas.clientHeight}px`;
}

// ---- dragging a vertex of a panel mesh (edit mode) ---------------------------------------------
// A press on the mesh picks the panel corner under it (Session.pickPanelVertex, in the worker);
// moving the pointer then drags that vertex in the plane through it facing the view. The worker
// restarts the run with the vertex held (Session.dragVertex) and steps it while the pointer
// moves. The next pointer position goes once the run for the one before has finished (the
// latest position wins) and starts from that result, which the worker commits (a waypoint); a
// run that ended short of its target is not a waypoint, the next one starts from the waypoint
// before. So the mesh follows the pointer wherever it goes, each run a short warm-started one,
// and a drag is a function of its waypoints: on release they are committed to the URL (`edits`),
// so Undo replays the drags before it, bit for bit. (Starting every position from the drag's
// start instead makes the result independent of the path, but its cost grows with the distance
// from the start: 0.9-1 s after release for 1 024 quads, against a single stage here.)
let editMode = false;
// Drags and reshapes are numbered; the worker's states carry the number of the last it took, so
// the page knows when the run on show is the one for the last position sent (a state of an
// earlier position may say `done` while the last one still runs).
let dragSeq = 0;
let dragPending = false;

function postNumbered(type, msg) {
  dragSeq += 1;
  dragPending = true;
  solver.post(type, { ...msg, seq: dragSeq });
}

let drag = null; // { id, x, y, origin, direction, vertex, point, group, start, inFlight, sent, finished, solved, path }

/** Whether the run on show is a panel mesh whose vertices can be dragged (a PQ mesh scene or an
 * opened panel mesh; not a P-Hex run, not a developable strip). */
function editable(m) {
  return !!m && m.level !== undefined && m.maxDeterminant === undefined;
}

function setEditMode(on) {
  editMode = on;
  setProp($('edit-vertices'), 'ariaPressed', on ? 'true' : 'false');
  canvas.classList.toggle('editing', on);
  if (!on && selection?.size) selection.clear();
  net?.show(on);
  dirty = true;
}

function rayAt(x, y) {
  const nx = (x / canvas.clientWidth) * 2 - 1, ny = 1 - (y / canvas.clientHeight) * 2;
  const r = viewer.pickRay(nx, ny);
  return { origin: Array.from(r.slice(0, 3)), direction: Array.from(r.slice(3, 6)) };
}

function dragStart(e) {
  const r = canvas.getBoundingClientRect();
  const x = e.clientX - r.left, y = e.clientY - r.top;
  try {
    const ray = rayAt(x, y);
    drag = { id: e.pointerId, x, y, ...ray, vertex: null, point: null, group: [], start: true, inFlight: false, sent: null, finished: false, solved: false, path: [] };
    solver.post('pick', { origin: ray.origin, direction: ray.direction, panels: true, drag: true });
  } catch (e2) { drag = null; reportError(e2.message ?? String(e2), 'edit-vertices'); }
}

function dragPicked(m) {
  if (!drag) return;
  if (m.error || !m.pick) { drag = null; if (m.error) reportError(m.error, 'edit-vertices'); return; }
  drag.vertex = m.pick.vertex;
  drag.point = m.pick.point;
  // A selected vertex takes the selection along; any other one is dragged alone.
  if (selection.has(drag.vertex)) drag.group = selection.groupOf(drag.vertex);
  else if (selection.size) { selection.clear(); dirty = true; }
  sendDrag();
}

/** The pointer's point on the plane a drag `d` moves in: through the picked point `d.point`,
 * normal to the press's view ray `d.direction`, under the pointer at (`d.x`, `d.y`) (null when
 * the ray runs along the plane). Vertex drags and control point drags alike. */
function dragPoint(d) {
  const { origin: o, direction: v } = rayAt(d.x, d.y);
  const n = d.direction, p = d.point;
  const vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
  if (Math.abs(vn) < 1e-9) return null;
  const t = ((p[0] - o[0]) * n[0] + (p[1] - o[1]) * n[1] + (p[2] - o[2]) * n[2]) / vn;
  return [o[0] + t * v[0], o[1] + t * v[1], o[2] + t * v[2]];
}

function sendDrag() {
  if (!drag || drag.vertex === null || drag.inFlight || !(drag.start || drag.finished)) return;
  let q;
  try { q = dragPoint(drag); } catch { q = null; }
  if (!q || (drag.sent && q.every((c, k) => c === drag.sent[k]))) return;
  postDrag(drag, q);
  followGroup(drag);
}

/** Sends drag position `q`: from the last result when its run reached its target (which makes
 * the position before a waypoint), else from the last waypoint. */
function postDrag(d, q) {
  const commit = d.start || d.solved;
  if (commit && !d.start) d.path.push(d.sent);
  d.inFlight = true;
  d.sent = q;
  d.finished = false;
  d.solved = false;
  postNumbered('drag', { vertex: d.vertex, point: q, group: d.group, start: commit });
  d.start = false;
}

/** A state arrived with `phase`: once the run has finished (`done`: it reached its target) the
 * next pointer position may go. */
function dragStateArrived(phase) {
  if (!drag) return;
  drag.inFlight = false;
  drag.finished = phase === 'done' || phase === 'warning';
  drag.solved = phase === 'done';
  sendDrag();
}

function dragEnd() {
  const d = drag;
  drag = null;
  if (!d || d.vertex === null) return;
  // The last position goes even if a state is still in flight (the worker takes them in order).
  try {
    const q = dragPoint(d);
    if (q && !(d.sent && q.every((c, k) => c === d.sent[k]))) postDrag(d, q);
  } catch { /* the last sent position stands */ }
  if (!d.sent) return;
  if (d.group.length) {
    selection.commit(d.sent.map((c, k) => c - d.point[k]));
    dirty = true;
  }
  config.edits = [...config.edits, { v: d.vertex, group: d.group, path: [...d.path, d.sent] }];
  welcome = false;
  syncHash();
}

// ---- dragging a control point of an opened NURBS surface (edit mode) -------------------------
// A press near a control point of the drawn net picks it; moving the pointer drags it in the
// plane through it facing the view. Each position sent is a move (Session.moveControlPoint):
// the worker reshapes the surface and the panelling shown follows it (the hexagons moved with
// the surface, then optimised), stepping it state by state. The next pointer position goes once
// that run has ended (the latest position wins), so every position starts from a finished run,
// and a drag is a function of its positions: on release they are committed to the URL (`cp`,
// one entry a move), a reload or Undo replays them bit for bit, and the release costs one short
// move rather than the whole drag again.
let netDrag = null; // { id, x, y, index, point, direction, inFlight, sent, seq, path }

function netDragStart(e) {
  const r = canvas.getBoundingClientRect();
  const x = e.clientX - r.left, y = e.clientY - r.top;
  const index = net.pick(x, y, (...p) => viewer.project(...p));
  if (index < 0) return false;
  const { direction } = rayAt(x, y);
  netDrag = { id: e.pointerId, x, y, index, point: net.point(index), direction, inFlight: false, sent: null, seq: null, path: [] };
  net.active = index;
  userMoved = true; // the view stays put while the panelling follows
  dirty = true;
  return true;
}

/** Sends the pointer's position as the next move once the run for the last one has ended; the
 * release's goes at once (the worker runs the last one to its end first, Session.moveControlPoint). */
function sendReshape(d = netDrag, release = false) {
  if (!d || (d.inFlight && !release)) return;
  const most = schema().maxControlPointMoves;
  if (config.imported.controlPoints.length + d.path.length >= most) {
    reportError(`this design has ${most} control-point moves, the most a reload replays; Undo frees some`, 'edit-vertices');
    return;
  }
  let q;
  try { q = dragPoint(d); } catch { q = null; }
  if (!q || (d.sent && q.every((c, k) => c === d.sent[k]))) return;
  const p = net.toDesign(q);
  d.inFlight = true;
  d.sent = q;
  d.path.push(p);
  postNumbered('reshape', { index: d.index, point: p });
  d.seq = dragSeq;
  net.place(d.index, q);
  dirty = true;
}

/** A state arrived with `phase`: once the run for the last position sent has ended, the next
 * may go. */
function netStateArrived(seq, phase) {
  if (!netDrag || seq !== netDrag.seq || !['done', 'warning'].includes(phase)) return;
  netDrag.inFlight = false;
  sendReshape();
}

function netDragEnd() {
  const d = netDrag;
  netDrag = null;
  net.active = -1;
  dirty = true;
  if (!d) return;
  sendReshape(d, true);
  if (!d.path.length) return;
  config.imported.controlPoints = [...config.imported.controlPoints, ...d.path.map((p) => [d.index, ...p])];
  welcome = false;
  syncHash();
}

/** The selection's markers follow a group drag by its translation so far. */
function followGroup(d) {
  if (!d.group.length || !d.sent) return;
  selection.follow(d.sent.map((c, k) => c - d.point[k]));
  dirty = true;
}

// ---- box selection (Shift-drag in edit mode; box-select.js) ------------------------------------
function boxEnd() {
  const rect = selection.end();
  if (!rect) return;
  try {
    solver.post('select', { viewProj: Array.from(viewer.viewProj()), rect });
  } catch (e) { reportError(e.message ?? String(e), 'edit-vertices'); }
}

function onSelection(m) {
  if (m.error) { reportError(m.error, 'edit-vertices'); return; }
  selection.set(m);
  dirty = true;
}

function wireInput() {
  const pointers = new Map();
  let pinch = 0;
  let down = null; // where a one-finger press started: a release near it is a click (pick)
  // The pointer in canvas CSS pixels.
  const local = (e) => {
    const r = canvas.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  };
  canvas.addEventListener('pointerdown', (e) => {
    canvas.setPointerCapture(e.pointerId);
    if (editMode && pointers.size === 0 && running && net.available) {
      if (netDragStart(e)) return;
    } else if (editMode && pointers.size === 0 && running) {
      if (e.shiftKey) selection.begin(...local(e));
      else dragStart(e);
      return;
    }
    pointers.set(e.pointerId, e);
    down = pointers.size === 1 ? { id: e.pointerId, x: e.clientX, y: e.clientY, moved: false } : null;
  });
  canvas.addEventListener('pointermove', (e) => {
    if (selection.active) {
      selection.move(...local(e));
      return;
    }
    for (const [d, send] of [[netDrag, sendReshape], [drag, sendDrag]]) {
      if (d && d.id === e.pointerId) {
        [d.x, d.y] = local(e);
        send();
        return;
      }
    }
    const prev = pointers.get(e.pointerId);
    if (!prev) return;
    if (down && Math.hypot(e.clientX - down.x, e.clientY - down.y) > 4) down.moved = true;
    if (down && !down.moved) return;
    pointers.set(e.pointerId, e);
    if (pointers.size === 1) {
      viewer.orbit((e.clientX - prev.clientX) * 0.008, (e.clientY - prev.clientY) * 0.008);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const d = Math.hypot(a.clientX - b.clientX, a.clientY - b.clientY);
      if (pinch > 0) viewer.zoom(pinch / d);
      pinch = d;
    }
    cameraMoved();
  });
  const up = (e) => { pointers.delete(e.pointerId); pinch = 0; };
  canvas.addEventListener('pointerup', (e) => {
    if (selection.active) { boxEnd(); return; }
    if (netDrag && netDrag.id === e.pointerId) { netDragEnd(); return; }
    if (drag && drag.id === e.pointerId) { dragEnd(); return; }
    const click = down && down.id === e.pointerId && !down.moved;
    down = null;
    up(e);
    if (click) pickAt(...local(e));
  });
  canvas.addEventListener('pointercancel', (e) => {
    if (drag && drag.id === e.pointerId) dragEnd();
    if (netDrag && netDrag.id === e.pointerId) netDragEnd();
    selection.end();
    up(e);
  });
  canvas.addEventListener('wheel', (e) => { e.preventDefault(); viewer.zoom(Math.exp(e.deltaY * 0.001)); cameraMoved(); }, { passive: false });
}

function frame() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; viewer.resize(w, h); dirty = true; }
  viewer.poll();
  if (dirty) {
    dirty = false;
    const t0 = performance.now();
    try {
      viewer.render();
      if (pickedPoint) placeMarker();
      if (selection?.size) selection.draw((x, y, z) => viewer.project(x, y, z));
      net?.draw((x, y, z) => viewer.project(x, y, z));
      noteTask('render', t0);
      if (document.body.dataset.ready !== 'true' && settled) {
        document.body.dataset.firstFrameMs = performance.now().toFixed(0);
        document.body.dataset.ready = 'true';
      }
    } catch (e) {
      showStatus(`${viewer.backend} · ${e.message ?? e}`, true);
    }
  }
  requestAnimationFrame(frame);
}

// ---- controls -----------------------------------------------------------------------------------
function rebuildFields() {
  describe(config);
  buildFields(fieldsBox, config, {
    catalog: ctx.catalog,
    torusParams: TORUS,
    defaults: ctx.defaults,
    // One field changed: try the current configuration with that change; the core decides.
    onChange: (apply, field, rebuild = false) => {
      const next = structuredClone(config);
      apply(next);
      next.steps = 1;
      next.edits = [];
      next.camera = null;
      if (rebuild) { config = next; rebuildFields(); }
      load(next, { reframe: true, field });
    },
  });
}

/** The colour legend of the current mode, its caption in the design's units. */
function showLegend() {
  const edge = lastMetrics?.meanEdgeM ?? config.panelEdge;
  drawLegend($('legend'), colorLegend(config.color), legendCaption(config.color, edge));
}

function setColorMode(mode) {
  config.color = mode;
  showLegend();
  if (running) solver.post('mode', { mode });
  syncHash();
}

function restore(hash) {
  const next = readHash(hash, { scenes: ctx.scenes, catalog: ctx.catalog, torusParams: TORUS });
  config = { ...next, steps: 1 };
  pendingCamera = next.camera;
  $('scene-select').value = next.scene;
  $('color-mode').value = next.color;
  $('panel-edge').classList.remove('invalid');
  $('panel-edge-error').textContent = '';
  $('panel-edge').value = String(next.panelEdge);
  $('toggle-offset').checked = next.layers.offset;
  $('toggle-support').checked = next.layers.support;
  $('offset-distance').value = String(next.layers.distance);
  showLayerError('');
  showLegend();
  clearFieldErrors(fieldsBox);
  rebuildFields();
  load(next, { reframe: !next.camera });
}

async function main() {
  try {
    ({ MeshData, Viewer, colorLegend, dupinVersion, freeDefaults, pageSchema, sceneDescription, sceneNames, surfaceCatalog, torusMesh } = await loadWasm());
    const schema = pageSchema();
    useSchema(schema);
    TORUS = Object.fromEntries(schema.torus.map((p) => [p.key, { label: p.key, value: p.default }]));
    config = defaults();
    ctx = { scenes: sceneNames(), catalog: surfaceCatalog(), defaults: freeDefaults() };
    solver = new Solver(workerUrl(), { onState, onError, onExport, onPick, onFault, onSelection });
    canvas.width = Math.max(1, canvas.clientWidth);
    canvas.height = Math.max(1, canvas.clientHeight);
    let exports;
    ({ view: viewer, exports } = await openView((w) => w.Viewer.create(canvas, forcedWebgl2)));
    ({ MeshData, Viewer, colorLegend, dupinVersion, freeDefaults, pageSchema, sceneDescription, sceneNames, surfaceCatalog, torusMesh } = exports);
    await solver.ready;
  } catch (e) {
    showStatus(`Cannot start: ${e.message ?? e}`, true);
    return;
  }
  Object.assign(marker, { className: 'pick-marker', hidden: true });
  marker.dataset.testid = 'pick-marker';
  canvas.after(marker);
  selection = new BoxSelection(canvas, $('selection'));
  net = new ControlNetOverlay(canvas);
  fillScenePicker($('scene-select'), ctx.scenes);
  initTeach();
  initHexd2d();
  initPresent(() => mesh);
  $('import-file').addEventListener('change', (e) => { openDesign(e.target.files[0]); e.target.value = ''; });
  // Drop a design anywhere on the page.
  document.addEventListener('dragover', (e) => { if (e.dataTransfer?.types.includes('Files')) e.preventDefault(); });
  document.addEventListener('drop', (e) => {
    if (!e.dataTransfer?.files.length) return;
    e.preventDefault();
    openDesign(e.dataTransfer.files[0]);
  });
  $('scene-select').addEventListener('change', (e) => {
    welcome = false;
    const next = defaults();
    Object.assign(next, { scene: e.target.value, color: config.color, panelEdge: config.panelEdge, layers: config.layers, backend: config.backend });
    if (next.scene === 'torus') for (const [k, s] of Object.entries(TORUS)) next.params[k] = s.value;
    if (next.scene === IMPORTED) next.imported.name = opened?.name ?? null;
    if (next.scene === FREE) {
      const s = ctx.catalog.find((x) => x.name === next.free.surface) ?? ctx.catalog[0];
      next.free.surface = s.name;
      for (const p of s.params) next.params[p.key] = p.default;
    }
    config = next;
    rebuildFields();
    load(next, { reframe: true });
  });
  window.addEventListener('hashchange', () => { if (location.hash !== writeHash(config)) restore(location.hash); });
  $('step').addEventListener('click', () => solver.post('step'));
  $('play').addEventListener('click', () => {
    solver.post(playing ? 'pause' : 'play');
    playing = !playing;
    if (!playing) syncHash(); // the URL was left behind while playing (showPanel)
    updateButtons();
  });
  $('stop').addEventListener('click', stop);
  $('undo').addEventListener('click', () => undoRedo(false));
  $('edit-vertices').addEventListener('click', () => setEditMode(!editMode));
  $('redo').addEventListener('click', () => undoRedo(true));
  // Ctrl+Z, Ctrl+Shift+Z and Ctrl+Y (Cmd on a Mac), except in a text field, which keeps its own.
  document.addEventListener('keydown', (e) => {
    if (e.key === 'Escape' && selection.size && !e.target.closest?.('input, textarea, select')) { selection.clear(); dirty = true; return; }
    if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
    if (e.target.closest?.('input:not([type=checkbox]):not([type=range]), textarea')) return;
    const key = e.key.toLowerCase();
    if (key !== 'z' && key !== 'y') return;
    e.preventDefault();
    undoRedo(key === 'y' || e.shiftKey);
  });
  $('reset').addEventListener('click', () => { welcome = false; if (running) load({ ...config, steps: 1, edits: [] }, { reframe: true }); });
  $('color-mode').addEventListener('change', (e) => setColorMode(e.target.value));
  $('panel-edge').addEventListener('change', (e) => {
    const v = Number(e.target.value);
    const ok = e.target.value.trim() !== '' && Number.isFinite(v) && v > 0;
    const msg = $('panel-edge-error');
    msg.textContent = ok ? '' : 'panel edge must be a positive length in metres';
    e.target.classList.toggle('invalid', !ok);
    if (!ok) return;
    config.panelEdge = v;
    if (lastMetrics) showMetrics(metricsEl, lastMetrics, config);
    showLegend();
    syncHash();
  });
  $('toggle-offset').addEventListener('change', (e) => setLayers({ offset: e.target.checked }));
  $('toggle-support').addEventListener('change', (e) => setLayers({ support: e.target.checked }));
  $('offset-distance').addEventListener('change', (e) => {
    const v = Number(e.target.value);
    if (e.target.value.trim() === '' || !Number.isFinite(v) || v === 0) {
      showLayerError('face distance must be a number other than 0');
      return;
    }
    setLayers({ distance: v });
  });
  $('export-obj').addEventListener('click', () => {
    if (running) solver.post('export', { kind: 'obj' });
    else if (mesh) { try { onExport({ kind: 'obj', text: mesh.toObj() }); } catch (e) { showStatus(e.message, true); } }
  });
  $('export-json').addEventListener('click', () => solver.post('export', { kind: 'json' }));
  $('export-svg').addEventListener('click', () => solver.post('export', { kind: 'svg', panelEdge: config.panelEdge }));
  $('share-presentation').addEventListener('click', () => solver.post('export', { kind: 'share' }));
  for (const kind of ['dxf', 'csv', 'glb', '3dm']) $(`export-${kind}`).addEventListener('click', () => solver.post('export', { kind, panelEdge: config.panelEdge }));
  $('screenshot').addEventListener('click', async () => {
    try { download(`${config.scene}@2x.png`, await snapshotPng(2)); } catch (e) { showStatus(`${viewer.backend} · ${e.message ?? e}`, true); }
  });
  wireInput();
  // A link or reload of an opened design: the design kept in this browser, if any.
  if (readHash(location.hash, { scenes: ctx.scenes, catalog: ctx.catalog, torusParams: TORUS }).scene === IMPORTED) {
    opened = await loadDesign();
    if (opened) fillScenePicker($('scene-select'), ctx.scenes, opened.name);
  }
  if (location.hash === '' || location.hash === '#') {
    welcome = true;
    // Replayed to the end in the worker (about 0.1 s), so the first picture is the finished roof.
    restore(`#scene=${OPENING.scene}&steps=100000`);
  } else restore(location.hash);
  requestAnimationFrame(frame);
}

main();
