// The solver thread: a module worker that owns the `Session` (state and geometry in Rust) so
// the page's thread only draws. Protocol (all messages carry the load generation `gen`; stale
// ones are dropped on both sides):
//   in:  load {config, steps, mode, layers, file?, edits?} (file {name, bytes}: Session.fromFile; edits: drags to replay)
//        | step | play | pause | ack | mode {mode} | resync (the next state's mesh is whole)
//        | drag {vertex, point, group?, start} (Session.dragVertices; start: a new drag)
//        | select {viewProj, rect} (Session.verticesInRect: a box selection)
//        | reshape {index, point} (a dragged NURBS control point's next position:
//          Session.moveControlPoint)
//        | layers {layers} (offset/support, Session.setLayers) | export {kind, panelEdge} (obj, json, svg, dxf, csv, glb, 3dm)
//        | pick {origin, direction, panels} (a view ray; panels: Session.pickPanelVertex)
//        | fault {kind} (debugFault: a deliberate trap or out-of-memory, for recovery tests)
//   out: ready | state {metrics, steps, done, mesh: typed arrays (transferred), whole or, with
//        `appendTo`, what the mesh added since the last state's (Session.meshSince), layers:
//        {unavailable, info}} | error {message, field}
//        | export {kind, text} | pick {panels, pick | error} (Session.pickVertex's or pickPanelVertex's answer)
//        error {fatal: true} after a wasm trap: the module is unusable and the page restarts us
// The page's build of the module (wasm.js: `build=gl` for the WebGL2 one, which the page has
// already fetched; the solvers are the same in both).
const gl = new URL(self.location.href).searchParams.get('build') === 'gl';
const { default: init, Session, debugFault } = await import(gl ? './pkg-gl/dupin_web.js' : './pkg/dupin_web.js');

let session = null;
let gen = 0;
let steps = 0;
let mode = null; // colour mode; null: Session.mesh's default
let playing = false;
let lastMetrics = null;
let layers = null; // the page's offset/support settings, applied where the run has an offset
let dragSeq = null; // the last drag or reshape taken (the page's number): its states carry it
let dragRun = false; // the run was restarted by a drag: each state takes DRAG_FRAME_MS of steps

// Sets the layers on the session where it has an offset layer (else they stay off and the
// page shows Session.offsetUnavailable's reason).
function applyLayers() {
  if (session && !session.offsetUnavailable()) session.setLayers(layers);
}

// The key of the last mesh posted: a state whose mesh only grew since posts only what it added
// (Session.meshSince; the page appends it, shown-arrays.js).
let shownKey = null;

function meshMessage() {
  const m = session.meshSince(mode, shownKey);
  const appendTo = m.appendTo ?? null;
  shownKey = m.key ?? null;
  // The polygons travel too: presentation mode and OBJ need the panels, not their triangles.
  const mesh = { positions: m.positions, normals: m.normals, indices: m.indices, colors: m.colors, edges: m.edges, panelPositions: m.panelPositions, panelFaces: m.panelFaces, viewOrigin: m.viewOrigin, key: shownKey, appendTo };
  m.free();
  return mesh;
}

function send() {
  const t0 = performance.now();
  const mesh = meshMessage();
  const t1 = performance.now();
  const done = session.done();
  if (lastMetrics?.timing) {
    lastMetrics.timing.mesh = t1 - t0;
    overhead = lastMetrics.timing.metrics + (t1 - t0);
  }
  const layerState = { unavailable: session.offsetUnavailable() ?? null, info: session.layerInfo() };
  postMessage({ type: 'state', gen, metrics: lastMetrics, steps, done, playing: playing && !done, mesh, layers: layerState, dragSeq },
    [mesh.positions.buffer, mesh.normals.buffer, mesh.indices.buffer, mesh.colors.buffer, mesh.edges.buffer, mesh.panelPositions.buffer, mesh.panelFaces.buffer]);
  // Posting (structured clone of the metrics; the typed arrays are transferred) is timed for
  // the step log of the next state.
  postedAt = performance.now();
  postMs = postedAt - t1;
}

let postMs = 0;
let postedAt = 0;
// What the last state cost besides solving: its metrics and render buffers, and (playing) the
// wait for the page to draw it and acknowledge.
let overhead = 0;

// `ms` is a step as the contract's `session.step()` (solver + metrics), per step of the state;
// `timing` splits the worker's time per state: solver, metrics, render buffers (mesh) and the
// previous post; `stepsInState` counts the steps the state took.
//
// While playing (`batch`) a large mesh (BATCH_FACES or more) whose last state's overhead
// (metrics, mesh and the page's acknowledgement) was 30 ms or more, a state takes one step for
// every 10 ms of it, while their solve time stays under it (and 250 ms): revealing a large
// triangulation takes steps of a hundredth of a millisecond, and at 190k triangles the page
// takes 30 ms or more to draw and acknowledge each state, so a state per layer would make the
// round trips nearly the whole run (50 s for the reveal at 96k faces). Layers still appear a
// few at a time. The face threshold, not the time alone, decides whether a run batches
// at all, so every scene of the papers (at most about 10k faces) shows every step however
// loaded the machine is.
const BATCH_FACES = 50_000;
// A drag's state takes as many steps as fit in this (the rest of a 50 ms frame draws it).
const DRAG_FRAME_MS = 30;
// `budget`: keep stepping for that many milliseconds (a drag).
function stepOnce(batch = false, budget = 0) {
  const t0 = performance.now();
  const large = (lastMetrics?.faces ?? 0) >= BATCH_FACES;
  const most = batch && large && overhead >= 30 ? Math.ceil(overhead / 10) : 1;
  let k = 0;
  do {
    session.advance();
    k += 1;
  } while (!session.done() && ((k < most && performance.now() - t0 < Math.min(overhead, 250)) || performance.now() - t0 < budget));
  const t1 = performance.now();
  const m = session.metrics();
  const t2 = performance.now();
  m.ms = (t2 - t0) / k;
  m.stepsInState = k;
  m.timing = { solve: t1 - t0, metrics: t2 - t1, mesh: 0, prevPost: postMs };
  steps += k;
  lastMetrics = m;
}

// A wasm trap (a Rust panic or a failed allocation) poisons the module: every later call would
// trap too, so it is reported as fatal and the page replaces this worker.
function fail(e, field = null) {
  playing = false;
  const fatal = e instanceof WebAssembly.RuntimeError;
  const message = fatal ? `wasm trap "${e.message}": out of memory or a bug` : e?.message ?? String(e);
  postMessage({ type: 'error', gen, message, field, fatal });
}

const handlers = {
  // A new configuration: built first, so a bad one leaves the running session untouched.
  load(msg) {
    let next;
    try {
      next = msg.file ? Session.fromFile(msg.file.name, msg.file.bytes, msg.config) : new Session(msg.config);
    } catch (e) {
      if (e instanceof WebAssembly.RuntimeError) { fail(e); return; }
      postMessage({ type: 'error', gen: msg.gen, active: gen, message: e?.message ?? String(e), field: msg.field ?? null, load: true });
      return;
    }
    session?.free();
    session = next;
    gen = msg.gen;
    shownKey = null;
    dragSeq = null;
    mode = msg.mode ?? mode;
    layers = msg.layers ?? null;
    playing = false;
    dragRun = false;
    steps = 0;
    overhead = 0;
    try { applyLayers(); } catch (e) { layers = null; fail(e, 'offset-distance'); }
    try {
      // Replays `steps` steps (a restored URL); the first step is always taken.
      const target = Math.max(1, msg.steps ?? 1);
      while (steps < target && !session.done()) stepOnce();
      // Committed drags, as the page made them: each starts from the run so far finished.
      const edits = msg.edits ?? [];
      // Each waypoint was committed where it was reached, the drag's end last.
      for (const { v, group, path } of edits) {
        for (const [x, y, z] of path) session.dragVertices(v, x, y, z, Uint32Array.from(group), true);
      }
      if (edits.length) while (!session.done()) stepOnce();
      send();
    } catch (e) { fail(e); }
  },
  step() {
    if (!session || session.done()) return;
    playing = false;
    try { stepOnce(); send(); } catch (e) { fail(e); }
  },
  play() {
    if (!session || session.done()) return;
    playing = true;
    try { stepOnce(true); send(); } catch (e) { fail(e); }
  },
  pause() { playing = false; },
  // The page missed a state and cannot add to what it holds: the next state is whole (now, or
  // the next step's while playing).
  resync() {
    shownKey = null;
    if (session && !(playing && !session.done())) { try { send(); } catch (e) { fail(e); } }
  },
  // A vertex drag: the run restarts from the mesh committed when the drag began, the vertex
  // held at `point`; steps for up to DRAG_FRAME_MS, then the state, then (playing) the ack loop
  // finishes the run.
  drag(msg) {
    if (!session) return;
    try {
      session.dragVertices(msg.vertex, msg.point[0], msg.point[1], msg.point[2], Uint32Array.from(msg.group ?? []), !!msg.start);
      dragSeq = msg.seq ?? null;
    } catch (e) {
      if (e instanceof WebAssembly.RuntimeError) { fail(e); return; }
      postMessage({ type: 'error', gen, message: e?.message ?? String(e), field: 'edit-vertices' });
      return;
    }
    playing = true;
    dragRun = true;
    try { stepOnce(false, DRAG_FRAME_MS); send(); } catch (e) { fail(e); }
  },
  fault(msg) {
    try { debugFault(msg.kind); } catch (e) { fail(e); }
  },
  // The page has drawn the last state: take the next step while playing (back-pressure keeps
  // the page from queueing meshes it cannot draw).
  ack(msg) {
    if (msg.gen !== gen || !playing || !session || session.done()) return;
    overhead += performance.now() - postedAt;
    setTimeout(() => {
      if (!playing || !session || session.done()) return;
      try { stepOnce(true, dragRun ? DRAG_FRAME_MS : 0); send(); } catch (e) { fail(e); }
    }, 0);
  },
  layers(msg) {
    const old = layers;
    layers = msg.layers;
    try { applyLayers(); } catch (e) { layers = old; fail(e, 'offset-distance'); return; }
    if (session) { try { send(); } catch (e) { fail(e, 'offset-distance'); } }
  },
  mode(msg) {
    mode = msg.mode;
    if (session) { try { send(); } catch (e) { fail(e, 'color-mode'); } }
  },
  pick(msg) {
    if (!session) return;
    try {
      // A panel mesh picks its design vertices (anchors); P-Hex its triangulation's stars.
      const pick = msg.panels ? session.pickPanelVertex(msg.origin, msg.direction) : session.pickVertex(msg.origin, msg.direction);
      postMessage({ type: 'pick', gen, panels: !!msg.panels, drag: !!msg.drag, pick });
    } catch (e) { postMessage({ type: 'pick', gen, drag: !!msg.drag, error: e?.message ?? String(e) }); }
  },
  // A dragged NURBS control point's next position: the run shown is run to its end if it has
  // not ended, the surface reshaped and the panelling follows it, its steps counted from there
  // (a reload replays the moves, then that many steps).
  reshape(msg) {
    if (!session) return;
    try {
      session.moveControlPoint(msg.index, msg.point[0], msg.point[1], msg.point[2]);
      dragSeq = msg.seq ?? null;
    } catch (e) {
      if (e instanceof WebAssembly.RuntimeError) { fail(e); return; }
      postMessage({ type: 'error', gen, message: e?.message ?? String(e), field: 'edit-vertices' });
      return;
    }
    steps = 0;
    playing = true;
    dragRun = true;
    try { stepOnce(false, DRAG_FRAME_MS); send(); } catch (e) { fail(e); }
  },
  // A box selection: the panel-mesh vertices projected inside `rect` (NDC corners).
  select(msg) {
    if (!session) return;
    try {
      const [x0, y0, x1, y1] = msg.rect;
      const sel = session.verticesInRect(msg.viewProj, x0, y0, x1, y1);
      postMessage({ type: 'selection', gen, vertices: sel.vertices, points: sel.points });
    } catch (e) {
      if (e instanceof WebAssembly.RuntimeError) { fail(e); return; }
      postMessage({ type: 'selection', gen, error: e?.message ?? String(e) });
    }
  },
  export(msg) {
    if (!session) return;
    try {
      const exports = {
        obj: () => session.exportObj(),
        json: () => session.exportJson(),
        share: () => session.exportJson(), // for the presentation file (share.js)
        svg: () => session.exportSvg(msg.panelEdge),
        dxf: () => session.exportDxf(msg.panelEdge),
        csv: () => session.exportCsv(msg.panelEdge),
        glb: () => session.exportGlb(msg.panelEdge), // bytes
        '3dm': () => session.exportPanels(msg.panelEdge), // panels for rhino.js to write
      };
      const text = exports[msg.kind]();
      postMessage({ type: 'export', gen, kind: msg.kind, text });
    } catch (e) { fail(e, `export-${msg.kind}`); }
  },
};

const queue = [];
onmessage = (e) => queue.push(e.data);
await init();
onmessage = (e) => handlers[e.data.type]?.(e.data);
for (const m of queue) handlers[m.type]?.(m);
postMessage({ type: 'ready' });
