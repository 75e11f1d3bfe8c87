// The page's whole configuration and its URL-hash form. One object describes what is on
// screen: `scene` ('torus' preview, a contract scene, or 'free'), the torus or free-surface
// parameters, the free mode's run settings, the step count, colour mode, panel edge for mm
// figures, the offset and support layers (conical scenes), camera and backend.
export const FREE = 'free';
// A design the user opened (file input or drop): its bytes stay in the page, the hash records
// only `scene=imported` and how it is read.
export const IMPORTED = 'imported';
export const IMPORT_UNITS = ['mm', 'cm', 'm', 'in', 'ft'];
export const IMPORT_MODES = ['planar', 'conical', 'circular'];

// Names, defaults and bounds come from Rust (`pageSchema()`, lists start with the default),
// handed over once the wasm module has loaded.
let SCHEMA = null;
export function useSchema(s) { SCHEMA = s; }
export const schema = () => SCHEMA;

export function defaults() {
  return {
    scene: 'torus',
    params: {},
    // `read`: how the worker read the opened file ({ as, unit }), shown until the user picks.
    imported: { name: null, as: null, unit: null, method: 'prescribed', init: SCHEMA.initialisations[0].name, size: null, bound: null, lambda: null, mu: null, mode: 'planar', fixBoundary: false, anchors: [], closeness: null, toleranceMm: null, controlPoints: [], read: null },
    free: { surface: 'torus', method: SCHEMA.methods[0].name, init: SCHEMA.initialisations[0].name, size: null, bound: null, lambda: null, mu: null },
    steps: 1,
    // Committed vertex drags of a panel run, [vertex, x, y, z] each, replayed in order.
    edits: [],
    color: SCHEMA.colorModes[0],
    panelEdge: 1.5,
    layers: { offset: false, support: false, distance: SCHEMA.offsetDistance },
    camera: null,
    backend: 'auto',
  };
}

const num = (s) => (s === null || s.trim() === '' ? NaN : Number(s));

/** Parses a hash; unknown or malformed entries fall back to defaults (the page reports them). */
export function readHash(hash, { scenes, catalog, torusParams }) {
  const h = new URLSearchParams(hash.replace(/^#/, ''));
  const c = defaults();
  const name = h.get('scene');
  if (name === FREE || name === IMPORTED || scenes.includes(name) || name === 'torus') c.scene = name;
  if (c.scene === IMPORTED) {
    if (['surface', 'panels'].includes(h.get('as'))) c.imported.as = h.get('as');
    if (IMPORT_UNITS.includes(h.get('unit'))) c.imported.unit = h.get('unit');
    if (IMPORT_MODES.includes(h.get('mode'))) c.imported.mode = h.get('mode');
    c.imported.fixBoundary = h.get('fix') === '1';
    readRunSettings(h, c.imported);
    // Anchors as vertex indices `anchors=3.17.40` (dots stay readable in a URL).
    const anchors = (h.get('anchors') ?? '').split('.').filter((t) => /^\d+$/.test(t)).map(Number);
    c.imported.anchors = [...new Set(anchors)].slice(0, 100000);
    if (h.has('closeness')) c.imported.closeness = num(h.get('closeness'));
    if (h.has('tol')) c.imported.toleranceMm = num(h.get('tol'));
    // NURBS control-point moves `cp=4:2,2,2.4;4:2,2,2.5;0:0,0,-0.5` (index:x,y,z, one entry a
    // move, in order; the session refuses more than it replays).
    for (const e of (h.get('cp') ?? '').split(';').slice(0, 100000)) {
      const m = /^(\d+):([^,]+),([^,]+),([^,]+)$/.exec(e);
      const xyz = m ? [m[2], m[3], m[4]].map(Number) : [];
      const i = m ? Number(m[1]) : -1;
      if (m && i < 2 ** 31 && xyz.every(Number.isFinite)) {
        c.imported.controlPoints.push([i, ...xyz]);
      }
    }
  }
  if (c.scene === 'torus') {
    for (const [k, spec] of Object.entries(torusParams)) c.params[k] = h.has(k) ? num(h.get(k)) : spec.value;
  }
  if (c.scene === FREE) {
    const surface = catalog.find((s) => s.name === h.get('surface')) ?? catalog.find((s) => s.name === 'torus') ?? catalog[0];
    c.free.surface = surface.name;
    for (const p of surface.params) c.params[p.key] = h.has(`p.${p.key}`) ? num(h.get(`p.${p.key}`)) : p.default;
    readRunSettings(h, c.free);
  }
  // Vertex drags `edits=12:0.5,1,-0.25;40+41+47:1,2,3/1,2,3.5` (vertex:x,y,z, as many digits
  // as round-trip; `+` joins the box-selected vertices dragged along by the same translation,
  // written %2B, and a bare `+` of a typed hash reads as a space, so either joins; `/` separates
  // the waypoints of one drag, the last its end): `{ v, group, path }` each.
  if (c.scene !== 'torus') {
    for (const e of (h.get('edits') ?? '').split(';').slice(0, 1000)) {
      const m = /^(\d+(?:[+ ]\d+)*):([^:]+)$/.exec(e);
      const path = m ? m[2].split('/').slice(0, 10000).map((p) => p.split(',')) : [];
      const [v, ...group] = m ? m[1].split(/[+ ]/).map(Number) : [];
      // Vertex numbers past 2^31 would wrap crossing into wasm: dropped, as any malformed entry.
      if (m && [v, ...group].every((u) => u < 2 ** 31) && path.every((p) => p.length === 3 && p.every((x) => x.trim() !== '' && Number.isFinite(Number(x))))) {
        c.edits.push({ v, group, path: path.map((p) => p.map(Number)) });
      }
    }
  }
  // The torus preview does not step (writeHash leaves its steps out).
  const steps = Number(h.get('steps'));
  if (c.scene !== 'torus' && Number.isInteger(steps) && steps >= 1 && steps <= 100000) c.steps = steps;
  if (SCHEMA.colorModes.includes(h.get('color'))) c.color = h.get('color');
  const edge = Number(h.get('edge'));
  if (h.has('edge') && Number.isFinite(edge) && edge > 0) c.panelEdge = edge;
  c.layers.offset = h.get('offset') === '1';
  c.layers.support = h.get('support') === '1';
  const dist = Number(h.get('dist'));
  if (h.has('dist') && Number.isFinite(dist) && dist !== 0) c.layers.distance = dist;
  const cam = (h.get('cam') ?? '').split(',').map(Number);
  if (cam.length === 6 && cam.every(Number.isFinite)) c.camera = cam;
  if (h.get('backend') === 'webgl2') c.backend = 'webgl2';
  return c;
}

// The P-Hex run settings of the free mode, which an opened surface shares: method,
// initialisation, size, b, λ, μ (hash keys `method`, `init`, `size`, `bound`, `lambda`, `mu`).
const RUN_NUMBERS = ['size', 'bound', 'lambda', 'mu'];
function readRunSettings(h, into) {
  if (SCHEMA.methods.some((m) => m.name === h.get('method'))) into.method = h.get('method');
  if (SCHEMA.initialisations.some((m) => m.name === h.get('init'))) into.init = h.get('init');
  for (const k of RUN_NUMBERS) if (h.has(k)) into[k] = num(h.get(k));
}
function writeRunSettings(h, from, d) {
  if (from.method !== d.method) h.set('method', from.method);
  if (from.init !== d.init) h.set('init', from.init);
  for (const k of RUN_NUMBERS) if (from[k] !== null) h.set(k, String(from[k]));
}
function runSettings(from) {
  const out = { method: from.method, init: from.init };
  for (const k of RUN_NUMBERS) if (from[k] !== null) out[k] = from[k];
  return out;
}

export function writeHash(c) {
  const d = defaults();
  const h = new URLSearchParams({ scene: c.scene });
  if (c.scene === 'torus') for (const [k, v] of Object.entries(c.params)) h.set(k, String(v));
  if (c.scene === FREE) {
    h.set('surface', c.free.surface);
    for (const [k, v] of Object.entries(c.params)) h.set(`p.${k}`, String(v));
    h.set('method', c.free.method); // a free link always names its method
    writeRunSettings(h, c.free, d.free);
  }
  if (c.scene === IMPORTED) {
    if (c.imported.as) h.set('as', c.imported.as);
    if (c.imported.unit) h.set('unit', c.imported.unit);
    if (c.imported.mode !== d.imported.mode) h.set('mode', c.imported.mode);
    if (c.imported.fixBoundary) h.set('fix', '1');
    writeRunSettings(h, c.imported, d.imported);
    if (c.imported.anchors.length) h.set('anchors', c.imported.anchors.join('.'));
    if (c.imported.closeness !== null) h.set('closeness', String(c.imported.closeness));
    if (c.imported.toleranceMm !== null) h.set('tol', String(c.imported.toleranceMm));
    if (c.imported.controlPoints.length) h.set('cp', c.imported.controlPoints.map(([i, x, y, z]) => `${i}:${x},${y},${z}`).join(';'));
  }
  if (c.scene !== 'torus' && c.edits.length) h.set('edits', c.edits.map(({ v, group, path }) => `${[v, ...group].join('+')}:${path.map((p) => p.join(',')).join('/')}`).join(';'));
  if (c.scene !== 'torus') h.set('steps', String(c.steps));
  if (c.color !== d.color) h.set('color', c.color);
  if (c.panelEdge !== 1.5) h.set('edge', String(c.panelEdge));
  if (c.layers.offset) h.set('offset', '1');
  if (c.layers.support) h.set('support', '1');
  if (c.layers.distance !== d.layers.distance) h.set('dist', String(c.layers.distance));
  if (c.camera) h.set('cam', c.camera.map(String).join(','));
  if (c.backend !== 'auto') h.set('backend', c.backend);
  return '#' + h.toString();
}

/** The `Session` config of a stepped scene or free configuration (null for the torus preview). */
export function sessionConfig(c) {
  if (c.scene === 'torus') return null;
  if (c.scene === IMPORTED) {
    const i = c.imported;
    const out = { mode: i.mode, fixBoundary: i.fixBoundary, ...runSettings(i) };
    if (i.anchors.length) out.anchors = i.anchors;
    if (i.closeness !== null) out.closeness = i.closeness;
    if (i.toleranceMm !== null) out.toleranceMm = i.toleranceMm;
    if (i.controlPoints.length) out.controlPoints = i.controlPoints;
    if (i.as) out.importAs = i.as;
    if (i.unit) out.unit = i.unit;
    return out;
  }
  if (c.scene !== FREE) return { scene: c.scene };
  return { surface: c.free.surface, params: { ...c.params }, ...runSettings(c.free) };
}
