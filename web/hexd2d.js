// 2D tab: hexagonal Delaunay triangulation (Sußner & Greiner) step by step. The refinement, the
// cells, the dual triangulation and its angle histogram all come from wasm (`HexDelaunayLab`);
// this file handles clicks and drags and draws into 2D canvases.
import { wasm } from './wasm.js';
import { download as save } from './download.js';

const VIEW = 3.2; // half-height of the shown world square when everything fits inside it
const DOT = 4;    // radius of a drawn point, px

let lab = null;
let points = [];     // [x, y] world coordinates
let segments = [];   // [i, j]
let pendingSeg = null;
let notice = ''; // a one-off remark on the last click, shown once in the status
let cells = null;
let dual = null;
let inputError = null;
let panel, canvas, hist, statusEl, modeSel, toolSel, stepBtn, runBtn, speedSel;
let running = null; // the animation or chunked run in progress (a timer id), if any
let modes = [];      // [{ name, angleBounds: [min, max] }] from pageSchema, simple then extended

const el = (tag, attrs = {}, text) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
};

let viewHalf = VIEW; // grows so every point and the refined triangulation stay in the picture

/**
 * The half-size of the world square to show: VIEW, or more when the points or the refined
 * triangulation reach further. The empty cells around the bounding hexagon are only context and
 * may leave the picture: fitting them would zoom out at every click near the border.
 */
function fitView() {
  let far = 0;
  const reach = (xy) => { for (const c of xy) far = Math.max(far, Math.abs(c)); };
  if (dual && lab?.steps() > 0) reach(dual.vertices);
  reach(points.flat());
  viewHalf = Math.max(VIEW, far * 1.04);
}

function scale() { return Math.min(canvas.width, canvas.height) / (2 * viewHalf); }
function toScreen([x, y]) { const s = scale(); return [canvas.width / 2 + x * s, canvas.height / 2 - y * s]; }
function toWorld(px, py) { const s = scale(); return [(px - canvas.width / 2) / s, (canvas.height / 2 - py) / s]; }

/** Restarts the refinement on the current input; the core's refusal is shown inline. */
function restart() {
  try {
    lab?.free();
    lab = new wasm.HexDelaunayLab(modeSel.value);
    if (points.length > 0) lab.setInput(new Float64Array(points.flat()), new Uint32Array(segments.flat()));
    inputError = null;
  } catch (e) {
    inputError = String(e.message ?? e);
  }
  refresh();
}

function refresh() {
  try {
    cells = lab ? lab.cells() : null;
    dual = lab ? lab.dual() : null;
  } catch (e) { inputError = String(e.message ?? e); }
  fitView();
  draw();
  drawHistogram();
  const done = !lab || lab.done();
  stepBtn.disabled = done || !!inputError;
  runBtn.disabled = done || !!inputError;
  const tri = dual ? dual.triangles.length / 3 : 0;
  statusEl.dataset.done = String(done && !inputError && points.length > 0);
  statusEl.dataset.steps = String(lab ? lab.steps() : 0);
  statusEl.dataset.triangles = String(tri);
  statusEl.dataset.minAngle = tri ? dual.minAngle.toFixed(4) : '';
  statusEl.dataset.maxAngle = tri ? dual.maxAngle.toFixed(4) : '';
  statusEl.classList.toggle('error', !!inputError);
  const segmentHint = toolSel.value !== 'segments' ? ''
    : pendingSeg === null ? ' · segments: click a point (or empty space for a new one), then the other end'
      : ' · now click the segment\'s other end';
  const said = notice;
  notice = '';
  if (inputError) statusEl.textContent = inputError;
  else if (points.length === 0) statusEl.textContent = `Click to add points, drag to move them, or pick a point set.${segmentHint}`;
  else if (lab.steps() === 0) statusEl.textContent = `${points.length} points · ${segments.length} segments · press Step or Run to refine${segmentHint}${said}`;
  else statusEl.textContent = `${points.length} points · ${segments.length} segments · step ${lab.steps()}${done ? ' (done)' : ''} · ${tri} triangles · angles ${dual.minAngle.toFixed(1)}°–${dual.maxAngle.toFixed(1)}°${segmentHint}${said}`;
}

function draw() {
  const g = canvas.getContext('2d');
  g.fillStyle = '#101218';
  g.fillRect(0, 0, canvas.width, canvas.height);
  if (cells && cells.domain.length) {
    let k = 0;
    g.lineWidth = 1;
    cells.sizes.forEach((n, i) => {
      g.beginPath();
      for (let j = 0; j < n; j++) {
        const [x, y] = toScreen([cells.corners[2 * (k + j)], cells.corners[2 * (k + j) + 1]]);
        if (j === 0) g.moveTo(x, y); else g.lineTo(x, y);
      }
      g.closePath();
      g.fillStyle = cells.occupied[i] ? 'rgba(127,178,229,0.18)' : 'rgba(127,178,229,0.05)';
      g.fill();
      g.strokeStyle = 'rgba(127,178,229,0.45)';
      g.stroke();
      k += n;
    });
  }
  // Before the first step the dual is only the bounding hexagon's 7 cell centres: nothing to read.
  if (dual && dual.triangles.length && lab?.steps() > 0) {
    g.strokeStyle = '#e6e8ee';
    g.lineWidth = 0.8;
    g.beginPath();
    const v = dual.vertices;
    for (let t = 0; t < dual.triangles.length; t += 3) {
      const [a, b, c] = [0, 1, 2].map((k) => toScreen([v[2 * dual.triangles[t + k]], v[2 * dual.triangles[t + k] + 1]]));
      g.moveTo(...a); g.lineTo(...b); g.lineTo(...c); g.closePath();
    }
    g.stroke();
  }
  g.strokeStyle = '#ff9e64';
  g.lineWidth = 2;
  for (const [i, j] of segments) {
    g.beginPath(); g.moveTo(...toScreen(points[i])); g.lineTo(...toScreen(points[j])); g.stroke();
  }
  points.forEach((p, i) => {
    const [x, y] = toScreen(p);
    g.fillStyle = i === pendingSeg ? '#ff9e64' : '#f2c14e';
    g.beginPath(); g.arc(x, y, DOT, 0, Math.PI * 2); g.fill();
  });
}

function drawHistogram() {
  const g = hist.getContext('2d');
  const [w, h] = [hist.width, hist.height];
  g.fillStyle = '#101218';
  g.fillRect(0, 0, w, h);
  const x = (deg) => 20 + (deg / 180) * (w - 30);
  if (dual && dual.histogram.length) {
    const max = Math.max(1, ...dual.histogram);
    g.fillStyle = '#7fb2e5';
    dual.histogram.forEach((n, i) => {
      const bh = (n / max) * (h - 28);
      g.fillRect(x(i * dual.binDeg), h - 16 - bh, Math.max(1, x(dual.binDeg) - x(0) - 1), bh);
    });
  }
  // The tightest bounds (the last mode's) always; the chosen mode's too when they are looser.
  const tightest = modes[modes.length - 1];
  const marks = tightest.angleBounds.map((d) => [d, '#5fd39a']);
  if (modeSel.value !== tightest.name) marks.push(...modes.find((m) => m.name === modeSel.value).angleBounds.map((d) => [d, '#ff9e64']));
  g.font = '10px system-ui';
  for (const [deg, col] of marks) {
    g.strokeStyle = col; g.fillStyle = col;
    g.beginPath(); g.moveTo(x(deg), 4); g.lineTo(x(deg), h - 16); g.stroke();
    g.fillText(`${deg}°`, x(deg) + 2, 12);
  }
  g.fillStyle = '#8d93a3';
  // Axis labels in degrees, the last one right-aligned so that it stays inside the canvas.
  for (const deg of [0, 60, 120, 180]) {
    g.textAlign = deg === 180 ? 'right' : 'center';
    g.fillText(`${deg}°`, deg === 180 ? w - 2 : x(deg), h - 3);
  }
  g.textAlign = 'start';
}

/** Seeded point sets (so a class sees the same picture twice): uniform, clustered, on a line. */
function pointSet(kind) {
  let seed = 12345;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  const r = VIEW * 0.8;
  if (kind === 'random' || kind === 'dense') {
    return Array.from({ length: kind === 'dense' ? 300 : 30 }, () => [(2 * rnd() - 1) * r, (2 * rnd() - 1) * r]);
  }
  if (kind === 'clustered') {
    const centres = [[-1.2, 0.8], [1.1, -0.6], [0.2, 1.6]];
    return Array.from({ length: 45 }, (_, i) => {
      const [cx, cy] = centres[i % 3];
      const a = 2 * Math.PI * rnd(), d = 0.5 * Math.sqrt(rnd());
      return [cx + d * Math.cos(a), cy + d * Math.sin(a)];
    });
  }
  // On a line, with a little noise off it.
  return Array.from({ length: 16 }, (_, i) => [-r + (2 * r * i) / 15, 0.3 * (-r + (2 * r * i) / 15) + 0.02 * (rnd() - 0.5)]);
}

/** The picture as SVG: cells, the dual triangulation, segments and points, in canvas pixels. */
function pictureSvg() {
  const parts = [`<svg xmlns="http://www.w3.org/2000/svg" width="${canvas.width}" height="${canvas.height}" viewBox="0 0 ${canvas.width} ${canvas.height}">`,
    `<rect width="100%" height="100%" fill="#101218"/>`];
  const pt = (p) => toScreen(p).map((c) => c.toFixed(2)).join(',');
  if (cells && cells.domain.length) {
    let k = 0;
    cells.sizes.forEach((n, i) => {
      const corners = Array.from({ length: n }, (_, j) => pt([cells.corners[2 * (k + j)], cells.corners[2 * (k + j) + 1]]));
      parts.push(`<polygon points="${corners.join(' ')}" fill="rgba(127,178,229,${cells.occupied[i] ? 0.18 : 0.05})" stroke="rgba(127,178,229,0.45)"/>`);
      k += n;
    });
  }
  // Before the first step the dual is only the bounding hexagon's 7 cell centres: nothing to read.
  if (dual && dual.triangles.length && lab?.steps() > 0) {
    const v = dual.vertices;
    for (let t = 0; t < dual.triangles.length; t += 3) {
      const c = [0, 1, 2].map((q) => pt([v[2 * dual.triangles[t + q]], v[2 * dual.triangles[t + q] + 1]]));
      parts.push(`<polygon points="${c.join(' ')}" fill="none" stroke="#e6e8ee" stroke-width="0.8"/>`);
    }
  }
  for (const [i, j] of segments) {
    const [a, b] = [toScreen(points[i]), toScreen(points[j])];
    parts.push(`<line x1="${a[0]}" y1="${a[1]}" x2="${b[0]}" y2="${b[1]}" stroke="#ff9e64" stroke-width="2"/>`);
  }
  for (const p of points) {
    const [x, y] = toScreen(p);
    parts.push(`<circle cx="${x}" cy="${y}" r="4" fill="#f2c14e"/>`);
  }
  parts.push('</svg>');
  return parts.join('\n');
}

/** The point within `reach` px of (px, py), nearest first, or -1. */
function nearest(px, py, reach = 10) {
  let best = -1, bd = reach;
  points.forEach((p, i) => {
    const [x, y] = toScreen(p);
    const d = Math.hypot(x - px, y - py);
    if (d < bd) { bd = d; best = i; }
  });
  return best;
}

function wire() {
  let dragging = -1;
  let press = null; // where a press near a point started, to tell a click beside it from a drag
  const at = (e) => {
    const r = canvas.getBoundingClientRect();
    return [(e.clientX - r.left) * (canvas.width / r.width), (e.clientY - r.top) * (canvas.height / r.height)];
  };
  canvas.addEventListener('pointerdown', (e) => {
    const [px, py] = at(e);
    let i = nearest(px, py);
    if (toolSel.value === 'segments') {
      if (i < 0) { points.push(toWorld(px, py)); i = points.length - 1; }
      if (pendingSeg === null) pendingSeg = i;
      else { if (i !== pendingSeg) segments.push([pendingSeg, i]); pendingSeg = null; }
      restart();
      return;
    }
    if (i < 0) { points.push(toWorld(px, py)); restart(); return; }
    // Near a point: a drag moves it; a click that did not land on its dot still adds a point
    // (a grab radius larger than the dot must not swallow clicks beside it).
    dragging = i;
    press = { px, py, moved: false, onDot: nearest(px, py, DOT + 2) >= 0 };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (dragging < 0) return;
    const [px, py] = at(e);
    if (!press.moved && Math.hypot(px - press.px, py - press.py) < 3) return;
    press.moved = true;
    points[dragging] = toWorld(px, py);
    restart();
  });
  canvas.addEventListener('pointerup', () => {
    if (dragging >= 0 && !press.moved && !press.onDot) {
      points.push(toWorld(press.px, press.py));
      restart();
    } else if (dragging >= 0 && !press.moved) {
      // Said, so a click on a dot is not mistaken for a lost click.
      notice = ' · a point is already there: drag it to move it';
      refresh();
    }
    dragging = -1;
  });
  canvas.addEventListener('pointercancel', () => { dragging = -1; });
  stepBtn.addEventListener('click', () => {
    try { lab.step(); } catch (e) { inputError = String(e.message ?? e); }
    refresh();
  });
  runBtn.addEventListener('click', () => {
    clearTimeout(running);
    const perSecond = Number(speedSel.value);
    if (perSecond > 0) {
      // Animated: one step per tick with a redraw, so the subdivision can be watched.
      const tick = () => {
        if (!lab || lab.done() || inputError || panel.hidden) return;
        try { lab.step(); } catch (e) { inputError = String(e.message ?? e); }
        refresh();
        running = setTimeout(tick, 1000 / perSecond);
      };
      tick();
      return;
    }
    // At once: steps in slices of at most 30 ms (the page stays responsive), one redraw at the end.
    const slice = () => {
      const t0 = performance.now();
      while (lab && !lab.done() && !inputError && performance.now() - t0 < 30) {
        try { lab.step(); } catch (e) { inputError = String(e.message ?? e); }
      }
      if (lab && !lab.done() && !inputError) running = setTimeout(slice, 0);
      else refresh();
    };
    slice();
  });
  modeSel.addEventListener('change', restart);
  toolSel.addEventListener('change', () => { pendingSeg = null; refresh(); });
}

/** Adds the 2D tab button and panel to the page. */
export function initHexd2d() {
  panel = el('section', { class: 'hexd', 'data-testid': 'hexd-panel', hidden: '' });
  canvas = el('canvas', { 'data-testid': 'hexd-canvas', width: '560', height: '480', 'aria-label': 'Click to add points; drag to move' });
  hist = el('canvas', { 'data-testid': 'hexd-histogram', width: '300', height: '120', 'aria-label': 'Angle histogram' });
  statusEl = el('p', { 'data-testid': 'hexd-status', role: 'status', class: 'hexd-status' });
  modeSel = el('select', { 'data-testid': 'hexd-mode', 'aria-label': 'Refinement mode' });
  modes = wasm.pageSchema().hexDelaunayModes;
  modeSel.append(...modes.map((m) => new Option(`${m.name} (${m.angleBounds[0]}°–${m.angleBounds[1]}°)`, m.name)));
  const bounds = (m) => `[${m.angleBounds[0]}°, ${m.angleBounds[1]}°]`;
  toolSel = el('select', { 'data-testid': 'hexd-tool', 'aria-label': 'Tool' });
  toolSel.append(new Option('points', 'points'), new Option('segments', 'segments'));
  stepBtn = el('button', { type: 'button', 'data-testid': 'hexd-step' }, 'Step');
  runBtn = el('button', { type: 'button', 'data-testid': 'hexd-run' }, 'Run');
  speedSel = el('select', { 'data-testid': 'hexd-speed', 'aria-label': 'Run speed', title: 'Run: at once, or animated step by step' });
  speedSel.append(new Option('at once', '0'), new Option('animate: 4 steps/s', '4'), new Option('animate: 25 steps/s', '25'));
  const clear = el('button', { type: 'button', 'data-testid': 'hexd-clear' }, 'Clear');
  clear.addEventListener('click', () => { clearTimeout(running); points = []; segments = []; pendingSeg = null; restart(); });
  const setSel = el('select', { 'data-testid': 'hexd-points', 'aria-label': 'Point set' });
  setSel.append(new Option('point set…', ''), new Option('random (30)', 'random'), new Option('dense (300)', 'dense'), new Option('clustered (45)', 'clustered'), new Option('on a line (16)', 'line'));
  setSel.addEventListener('change', () => {
    if (!setSel.value) return;
    clearTimeout(running);
    points = pointSet(setSel.value);
    segments = [];
    pendingSeg = null;
    setSel.value = '';
    restart();
  });
  const png = el('button', { type: 'button', 'data-testid': 'hexd-png', title: 'the picture as PNG, for slides' }, 'PNG');
  png.addEventListener('click', () => canvas.toBlob((b) => b && save('hexagonal-delaunay.png', b), 'image/png'));
  const svg = el('button', { type: 'button', 'data-testid': 'hexd-svg', title: 'the picture as SVG, for slides' }, 'SVG');
  svg.addEventListener('click', () => save('hexagonal-delaunay.svg', new Blob([pictureSvg()], { type: 'image/svg+xml' })));
  const bar = el('div', { class: 'hexd-controls' });
  bar.append(modeSel, toolSel, setSel, stepBtn, runBtn, speedSel, clear, png, svg);
  const side = el('div', { class: 'hexd-side' });
  const note = el('p', { class: 'hint' }, `Hexagon cells (blue) are split one refinement step at a time; white: the dual triangulation. The histogram counts its angles; the ${modes[0].name} refinement keeps them in ${bounds(modes[0])} (section 4), the ${modes[1].name} one in ${bounds(modes[1])} (section 5).`);
  side.append(bar, statusEl, hist, note);
  panel.append(canvas, side);
  document.querySelector('main').append(panel);
  const toggle = el('button', { type: 'button', 'data-testid': 'hexd', 'aria-pressed': 'false' }, '2D Delaunay');
  toggle.addEventListener('click', () => {
    panel.hidden = !panel.hidden;
    toggle.setAttribute('aria-pressed', String(!panel.hidden));
  });
  document.querySelector('header .buttons')?.append(toggle);
  wire();
  restart();
}
