// Teaching inset: Dupin duality at one surface point (P-Hex paper, sections 3-5.1). All geometry
// comes from wasm (`DupinLesson`); this file draws its primitives as SVG and forwards drags. The
// lesson is either at a surface point (u, v) picked in the inset, or at a mesh vertex clicked in
// the 3D view (`showPick`, fed by `Session.pickVertex` in the worker).
import { wasm } from './wasm.js';
import { download as save } from './download.js';

const SVGNS = 'http://www.w3.org/2000/svg';
const el = (tag, attrs = {}, text) => {
  const e = tag.startsWith('svg:') ? document.createElementNS(SVGNS, tag.slice(4)) : document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
};

const COLORS = { indicatrix: '#7fb2e5', star: '#e6e8ee', conic: '#8d93a3', center: '#f2c14e', hexagon: '#5fd39a',
  invalid: '#ff7b72', dragged: '#c58af9', conjugate: '#f2c14e', construct: '#ff9e64' };

let lesson = null;
let state = null;
let steps = null;
let stepIndex = -1;
let panel, svg, layer, verdictEl, reasonEl, condEl, captionEl, errorEl, surfaceSel, uIn, vIn, sourceEl, toggleBtn;
let picked = null; // the mesh vertex the lesson is at (Session.pickVertex's answer), if any

function polyline(flat, stroke, extra = {}) {
  const pts = [];
  for (let i = 0; i + 1 < flat.length; i += 2) pts.push(`${flat[i]},${flat[i + 1]}`);
  return el('svg:polyline', { points: pts.join(' '), fill: 'none', stroke, 'vector-effect': 'non-scaling-stroke', ...extra });
}

function dot(x, y, r, fill, extra = {}) {
  return el('svg:circle', { cx: x, cy: y, r, fill, ...extra });
}

function label(x, y, text, size) {
  // Text is drawn un-flipped inside the y-flipped layer.
  const t = el('svg:text', { x, y: -y, 'font-size': size, fill: COLORS.construct, transform: 'scale(1,-1)' }, text);
  return t;
}

/** Half-width of the view: the lesson's extent, grown so that every construction point and
 * segment shown so far stays inside the inset. */
function viewExtent() {
  let E = state.extent;
  if (steps && stepIndex >= 0) {
    for (const s of steps.slice(0, stepIndex + 1)) {
      for (const [, x, y] of s.points) E = Math.max(E, 1.15 * Math.abs(x), 1.15 * Math.abs(y));
      for (const [x1, y1, x2, y2] of s.segments) E = Math.max(E, 1.05 * Math.max(Math.abs(x1), Math.abs(y1), Math.abs(x2), Math.abs(y2)));
    }
  }
  return E;
}

function draw() {
  if (!state) return;
  const E = viewExtent();
  svg.setAttribute('viewBox', `${-E} ${-E} ${2 * E} ${2 * E}`);
  const r = E * 0.03;
  const g = [];
  for (const c of state.indicatrix) g.push(polyline(c, COLORS.indicatrix, { 'stroke-width': 2 }));
  for (const d of state.asymptotes) {
    g.push(polyline([-4 * E * d[0], -4 * E * d[1], 4 * E * d[0], 4 * E * d[1]], COLORS.indicatrix, { 'stroke-dasharray': '3 4', 'stroke-width': 1 }));
  }
  for (const t of state.triangleConics) for (const c of t.curves) g.push(polyline(c, COLORS.conic, { 'stroke-width': 0.7, opacity: 0.7 }));
  for (const c of state.hexagonConic) g.push(polyline(c, COLORS.hexagon, { 'stroke-width': 1, 'stroke-dasharray': '2 3' }));
  const ring = state.ring;
  if (ring.length === 6) {
    for (let i = 0; i < 6; i++) {
      const [p, q] = [ring[i], ring[(i + 1) % 6]];
      g.push(polyline([0, 0, p[0], p[1]], COLORS.star, { 'stroke-width': 1.2 }));
      g.push(polyline([p[0], p[1], q[0], q[1]], COLORS.star, { 'stroke-width': 1.2 }));
    }
  }
  if (state.hexagon.length === 6) {
    const h = state.hexagon.flat();
    g.push(polyline([...h, h[0], h[1]], state.verdict === 'invalid' ? COLORS.invalid : COLORS.hexagon, { 'stroke-width': 2.5 }));
  }
  for (const t of state.triangleConics) g.push(dot(t.center[0], t.center[1], r * 0.6, COLORS.center));
  if (state.dragged && state.conjugate) {
    const [d, c] = [state.dragged, state.conjugate];
    const n = Math.hypot(d[0], d[1]) || 1;
    const L = E * 0.8;
    g.push(polyline([-L * d[0] / n, -L * d[1] / n, L * d[0] / n, L * d[1] / n], COLORS.dragged, { 'stroke-width': 1.2, 'stroke-dasharray': '6 3' }));
    g.push(polyline([-L * c[0], -L * c[1], L * c[0], L * c[1]], COLORS.conjugate, { 'stroke-width': 1.2, 'stroke-dasharray': '6 3' }));
  }
  if (steps && stepIndex >= 0) {
    for (const s of steps.slice(0, stepIndex + 1)) {
      for (const c of s.curves) g.push(polyline(c, COLORS.construct, { 'stroke-width': 1, opacity: 0.8 }));
      for (const [x1, y1, x2, y2] of s.segments) g.push(polyline([x1, y1, x2, y2], COLORS.construct, { 'stroke-width': 1.6 }));
      for (const [name, x, y] of s.points) { g.push(dot(x, y, r * 0.7, COLORS.construct)); g.push(label(x + r, y + r, name, E * 0.08)); }
    }
  }
  g.push(dot(0, 0, r, COLORS.star));
  ring.forEach(([x, y], i) => {
    const h = dot(x, y, r * 1.3, i < 2 ? '#ffffff' : COLORS.star, {
      'data-vertex': String(i), class: 'teach-handle', tabindex: '0', role: 'button',
      'aria-label': `star vertex ${i + 1} of 6 at (${x.toFixed(2)}, ${y.toFixed(2)}): arrow keys move it`,
    });
    h.addEventListener('pointerdown', (e) => startDrag(e, i));
    h.addEventListener('keydown', (e) => keyMove(e, i));
    g.push(h);
  });
  // Labels of the elements, for a class reading the picture: a legend in the top-left corner
  // (labels on the curves themselves collide where the elements meet at the centre).
  const fs = E * 0.06;
  const entries = [['Dupin indicatrix', COLORS.indicatrix], ['triangle star', COLORS.star]];
  if (state.hexagon.length === 6) entries.push(['Dupin hexagon', state.verdict === 'invalid' ? COLORS.invalid : COLORS.hexagon]);
  if (state.triangleConics.length) entries.push(['Dupin center', COLORS.center]);
  if (state.dragged && state.conjugate) entries.push(['dragged and conjugate directions', COLORS.conjugate]);
  entries.forEach(([text, fill], k) => {
    const y = E - fs * (1.4 + 1.25 * k);
    g.push(el('svg:rect', { x: -E + fs * 0.5, y: y - fs * 0.1, width: fs * 0.9, height: fs * 0.3, fill, class: 'teach-label' }));
    g.push(el('svg:text', { x: -E + fs * 1.7, y: -y, 'font-size': fs, fill, transform: 'scale(1,-1)', class: 'teach-label' }, text));
  });
  layer.replaceChildren(...g);
  if (focusIndex >= 0) layer.querySelector(`[data-vertex="${focusIndex}"]`)?.focus();
  verdictEl.textContent = state.verdict === 'undecided' ? `${state.kind} point: no verdict` : `${state.kind} point: star ${state.verdict}`;
  verdictEl.dataset.verdict = state.verdict;
  verdictEl.dataset.kind = state.kind;
  svg.dataset.star = state.star;
  svg.dataset.ring = JSON.stringify(state.ring);
  verdictEl.className = `teach-verdict ${state.verdict}`;
  reasonEl.textContent = state.reason;
  condEl.replaceChildren(...state.conditions.map((c) => el('li', { class: c.holds ? 'holds' : 'fails' }, `${c.holds ? '✓' : '✗'} ${c.text}`)));
  captionEl.textContent = steps && stepIndex >= 0
    ? `Step ${stepIndex + 1}/${steps.length}. ${steps[stepIndex].caption}`
    : (picked ? `Mesh vertex ${picked.vertex}: its six neighbours projected onto the tangent plane (section 6). The Dupin indicatrix is drawn scaled to the star. ` : '')
    + 'Tangent plane in the principal frame (x: k1, y: k2). Blue: the Dupin indicatrix (section 3); white: the projected triangle star; grey: each triangle\'s Dupin conic, yellow dots its Dupin center; green: the Dupin hexagon (section 4.1, Prop. 3). Drag a vertex: Props. 4 and 5 (section 4.2) decide validity; purple/yellow dashes: the dragged direction and its conjugate.';
}

function showError(e) {
  errorEl.textContent = e ? String(e.message ?? e) : '';
  delete errorEl.dataset.pickedVertex;
}

// Redrawing replaces the handles, so the drag is tracked on the <svg> itself.
let dragIndex = -1;

function startDrag(e, i) {
  e.preventDefault();
  e.stopPropagation();
  dragIndex = i;
  svg.setPointerCapture(e.pointerId);
}

function moveDrag(ev) {
  if (dragIndex < 0) return;
  const m = layer.getScreenCTM().inverse();
  const pt = new DOMPoint(ev.clientX, ev.clientY).matrixTransform(m);
  try {
    state = lesson.dragVertex(dragIndex, pt.x, pt.y);
    steps = null; stepIndex = -1;
    showError(null);
  } catch (err) { showError(err); }
  draw();
}

// Arrow keys move the focused star vertex by 5% of the view (Shift: 1%), as a drag would.
let focusIndex = -1;
function keyMove(e, i) {
  const d = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] }[e.key];
  if (!d || !state) return;
  e.preventDefault();
  const step = (e.shiftKey ? 0.01 : 0.05) * state.extent;
  const [x, y] = state.ring[i];
  try {
    state = lesson.dragVertex(i, x + d[0] * step, y + d[1] * step);
    steps = null; stepIndex = -1;
    showError(null);
  } catch (err) { showError(err); }
  focusIndex = i;
  draw();
  focusIndex = -1;
}

function load() {
  const spec = CATALOG.find((s) => s.name === surfaceSel.value);
  // The run's surface parameters when the inset shows the surface of a picked vertex.
  const params = pickedSurface?.name === spec.name ? { ...pickedSurface.params } : {};
  try {
    const u = Number(uIn.value), v = Number(vIn.value);
    if (uIn.value.trim() === '' || vIn.value.trim() === '' || !Number.isFinite(u) || !Number.isFinite(v)) throw new Error('u and v must be numbers');
    const next = new wasm.DupinLesson(spec.name, params, u, v);
    lesson?.free();
    lesson = next;
    setPicked(null, true);
    state = lesson.state();
    steps = null; stepIndex = -1;
    showError(null);
  } catch (e) { showError(e); }
  draw();
}

let pickedSurface = null; // { name, params } of the last picked vertex's run

function setPicked(pick, keepSurface = false) {
  picked = pick;
  if (!keepSurface) pickedSurface = null;
  if (pick) {
    // The controls show where the lesson is: the run's surface (when it is a library surface)
    // at the vertex's (u, v).
    uIn.value = pick.uv[0].toFixed(4);
    vIn.value = pick.uv[1].toFixed(4);
    if (CATALOG.some((c) => c.name === pick.surface)) {
      surfaceSel.value = pick.surface;
      pickedSurface = { name: pick.surface, params: pick.params ?? {} };
    }
    svg.dataset.pickedVertex = String(pick.vertex);
    svg.dataset.pickedNeighbours = pick.neighbours.join(',');
    const where = CATALOG.some((c) => c.name === pick.surface) ? `${pick.surface} ` : '';
    sourceEl.textContent = `Mesh vertex ${pick.vertex} on ${where}at (u, v) = (${pick.uv.map((x) => x.toFixed(3)).join(', ')}), k1 = ${pick.k1.toPrecision(3)}, k2 = ${pick.k2.toPrecision(3)}`;
  } else {
    delete svg.dataset.pickedVertex;
    delete svg.dataset.pickedNeighbours;
    sourceEl.textContent = 'Surface point (u, v) above, or click a vertex of the mesh.';
  }
}

function open() {
  panel.hidden = false;
  toggleBtn.setAttribute('aria-pressed', 'true');
}

/**
 * Opens the inset at a clicked mesh vertex: `pick` is `Session.pickVertex`'s answer (null when
 * the click missed the mesh), `error` the worker's message. Returns the picked vertex (for the
 * 3D marker) or null. A vertex without a complete star keeps the last lesson and shows why.
 */
export function showPick(pick, error) {
  open();
  if (error || !pick) {
    showError(error ?? 'No mesh under the click: click a vertex of the P-Hex mesh.');
    return null;
  }
  if (pick.message) {
    showError(`Vertex ${pick.vertex}: ${pick.message}`);
    errorEl.dataset.pickedVertex = String(pick.vertex);
    return pick;
  }
  try {
    const next = wasm.DupinLesson.fromStar(pick);
    lesson?.free();
    lesson = next;
    state = lesson.state();
    steps = null; stepIndex = -1;
    setPicked(pick);
    showError(null);
  } catch (e) { showError(e); }
  draw();
  return pick;
}

let CATALOG = [];

/** The inset as a standalone SVG document (its current picture, labels included). */
function insetSvg() {
  const copy = svg.cloneNode(true);
  copy.setAttribute('xmlns', SVGNS);
  copy.setAttribute('width', '600');
  copy.setAttribute('height', '600');
  for (const h of copy.querySelectorAll('[tabindex]')) { h.removeAttribute('tabindex'); h.removeAttribute('role'); }
  return new XMLSerializer().serializeToString(copy);
}

/** The inset rendered to a PNG blob at `scale` x 300 px. */
async function insetPng(scale) {
  const url = URL.createObjectURL(new Blob([insetSvg()], { type: 'image/svg+xml' }));
  try {
    const img = new Image();
    img.src = url;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = c.height = 300 * scale;
    c.getContext('2d').drawImage(img, 0, 0, c.width, c.height);
    return await new Promise((resolve, reject) => c.toBlob((b) => (b ? resolve(b) : reject(new Error('PNG export failed'))), 'image/png'));
  } finally {
    URL.revokeObjectURL(url);
  }
}

/** Adds the Teach button and the inset panel to the page. */
export function initTeach() {
  CATALOG = wasm.surfaceCatalog();
  panel = el('section', { class: 'teach', 'data-testid': 'teach-panel', hidden: '' });
  surfaceSel = el('select', { 'data-testid': 'teach-surface', 'aria-label': 'Surface' });
  for (const s of CATALOG) if (s.name !== 'bspline') surfaceSel.append(new Option(s.name, s.name));
  surfaceSel.value = 'torus';
  uIn = el('input', { type: 'number', step: '0.1', value: '0.3', 'data-testid': 'teach-u', 'aria-label': 'u' });
  vIn = el('input', { type: 'number', step: '0.1', value: '0.4', 'data-testid': 'teach-v', 'aria-label': 'v' });
  const stepBtn = el('button', { type: 'button', 'data-testid': 'teach-step', title: 'Section 5.1 construction, one step at a time' }, 'Ideal △ step');
  const backBtn = el('button', { type: 'button', 'data-testid': 'teach-step-back', title: 'Section 5.1 construction, one step back', 'aria-label': 'construction step back' }, '◀');
  const idealBtn = el('button', { type: 'button', 'data-testid': 'teach-ideal' }, 'Reset star');
  const bigBtn = el('button', { type: 'button', 'data-testid': 'teach-enlarge', 'aria-pressed': 'false', title: 'Fill the view with the inset (for a class)' }, 'Enlarge');
  const svgBtn = el('button', { type: 'button', 'data-testid': 'teach-svg', title: 'The inset as SVG, for slides' }, 'SVG');
  const pngBtn = el('button', { type: 'button', 'data-testid': 'teach-png', title: 'The inset as PNG (2x), for slides' }, 'PNG');
  const closeBtn = el('button', { type: 'button', 'data-testid': 'teach-close', 'aria-label': 'Close the inset (Escape)', title: 'Close (Escape)' }, '✕');
  const controls = el('div', { class: 'teach-controls' });
  const lab = (t, c) => { const l = el('label', {}, t); l.append(c); return l; };
  controls.append(lab('Surface ', surfaceSel), lab('u ', uIn), lab('v ', vIn), backBtn, stepBtn, idealBtn, bigBtn, svgBtn, pngBtn, closeBtn);
  svg = el('svg:svg', { 'data-testid': 'teach-inset', class: 'teach-inset', width: '300', height: '300', role: 'group', 'aria-label': 'Dupin indicatrix, triangle star and Dupin hexagon; its six star vertices move with the arrow keys' });
  svg.append(el('svg:rect', { x: '-1e6', y: '-1e6', width: '2e6', height: '2e6', fill: '#101218' }));
  layer = el('svg:g', { transform: 'scale(1,-1)' });
  svg.append(layer);
  verdictEl = el('p', { 'data-testid': 'teach-verdict', class: 'teach-verdict' });
  reasonEl = el('p', { class: 'teach-reason', 'data-testid': 'teach-reason' });
  condEl = el('ul', { class: 'teach-conditions' });
  captionEl = el('p', { class: 'teach-caption', 'data-testid': 'teach-caption' });
  errorEl = el('p', { class: 'field-error', 'data-testid': 'teach-error', role: 'alert' });
  sourceEl = el('p', { class: 'teach-caption', 'data-testid': 'teach-source' });
  panel.append(controls, sourceEl, svg, verdictEl, reasonEl, condEl, captionEl, errorEl);
  document.querySelector('main').append(panel);
  const toggle = el('button', { type: 'button', 'data-testid': 'teach', 'aria-pressed': 'false', title: 'Dupin duality inset; or click a mesh vertex in the 3D view' }, 'Teach');
  toggleBtn = toggle;
  toggle.addEventListener('click', () => {
    panel.hidden = !panel.hidden;
    toggle.setAttribute('aria-pressed', String(!panel.hidden));
    if (!panel.hidden && !lesson) load();
  });
  document.querySelector('header .buttons')?.append(toggle);
  setPicked(null);
  for (const c of [surfaceSel, uIn, vIn]) c.addEventListener('change', load);
  svg.addEventListener('pointermove', moveDrag);
  const endDrag = () => { dragIndex = -1; };
  svg.addEventListener('pointerup', endDrag);
  svg.addEventListener('pointercancel', endDrag);
  backBtn.addEventListener('click', () => {
    if (!steps || stepIndex < 0) return;
    stepIndex -= 1;
    draw();
  });
  const close = () => {
    panel.hidden = true;
    toggle.setAttribute('aria-pressed', 'false');
    toggle.focus();
  };
  closeBtn.addEventListener('click', close);
  document.addEventListener('keydown', (e) => { if (e.key === 'Escape' && !panel.hidden) close(); });
  bigBtn.addEventListener('click', () => {
    const big = panel.classList.toggle('teach-big');
    bigBtn.setAttribute('aria-pressed', String(big));
  });
  svgBtn.addEventListener('click', () => save('dupin-indicatrix.svg', new Blob([insetSvg()], { type: 'image/svg+xml' })));
  pngBtn.addEventListener('click', async () => {
    try { save('dupin-indicatrix.png', await insetPng(2)); } catch (e) { showError(e); }
  });
  stepBtn.addEventListener('click', () => {
    try {
      steps ??= lesson.idealTriangleSteps();
      stepIndex = stepIndex + 1 >= steps.length ? -1 : stepIndex + 1;
      showError(null);
    } catch (e) { showError(e); }
    draw();
  });
  idealBtn.addEventListener('click', () => {
    try { state = lesson.makeIdeal(); showError(null); } catch (e) { showError(e); }
    draw();
  });
}
