// Configuration controls: the scene picker and the parameter fields (torus preview, or the free
// mode's surface, parameters with slider + numeric field, method, size, b, lambda, mu). Every
// field has an inline message slot; `showFieldError` puts the core's error text there.
import { FREE, IMPORTED, IMPORT_MODES, IMPORT_UNITS, schema } from './config.js';

const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
};

const labelled = (text, e) => el('label', { className: 'field' }, el('span', { className: 'field-label', textContent: text }), e);

/** Fills the scene picker: torus preview, every contract scene, the free mode, and the
 * opened design (`imported: NAME`) when there is one. */
export function fillScenePicker(select, scenes, importedName = null) {
  select.replaceChildren(
    new Option('Torus (surface preview)', 'torus'),
    ...scenes.map((n) => new Option(n, n)),
    new Option('free: surface, method, size, b, λ, μ', FREE),
  );
  if (importedName) select.append(new Option(`imported: ${importedName}`, IMPORTED));
}

/** A labelled checkbox with a test id, calling `onToggle(checked)`. */
function checkbox(id, label, checked, title, onToggle) {
  const c = el('input', { type: 'checkbox', checked });
  c.dataset.testid = id;
  c.addEventListener('change', () => onToggle(c.checked));
  return el('label', { className: 'field', title }, c, ` ${label}`);
}

/** A select of `choices` ([value, label]) with a test id, calling `onPick(value)`. */
function choice(id, choices, value, onPick, title = '') {
  const s = el('select', { title });
  s.dataset.testid = id;
  s.append(...choices.map(([v, label]) => new Option(label, v)));
  s.value = value;
  s.addEventListener('change', () => onPick(s.value));
  return s;
}

/** The anchored vertices of a panel mesh: their count, how to set them, and a clear button. */
function anchorsField(anchors, onClear) {
  const text = el('span', { textContent: anchors.length ? `${anchors.length} anchored` : 'click a vertex to anchor it' });
  const clear = el('button', { type: 'button', textContent: 'clear', disabled: anchors.length === 0, title: 'release every anchor' });
  clear.dataset.testid = 'import-clear-anchors';
  clear.addEventListener('click', onClear);
  const msg = el('span', { className: 'field-error' });
  msg.dataset.testid = 'import-anchors-error';
  msg.dataset.for = 'import-anchors';
  const box = el('span', { className: 'field', title: 'anchors stay exactly where the file puts them: click a vertex in the view to add or remove one' },
    el('span', { className: 'field-label', textContent: 'anchors' }), text, clear, msg);
  box.dataset.testid = 'import-anchors';
  box.dataset.anchors = String(anchors.length);
  return box;
}

// One labelled field: a numeric input (optionally with a slider, linear or, with `log`, over
// decades) and its message slot.
function numberField({ id, label, value, min, max, step = 'any', slider = false, log = false, range: span = null, title = '', onCommit }) {
  const input = el('input', { type: 'number', step, value: value ?? '', title });
  if (min !== undefined) input.min = min;
  if (max !== undefined) input.max = max;
  input.dataset.testid = id;
  const msg = el('span', { className: 'field-error' });
  msg.dataset.testid = `${id}-error`;
  msg.dataset.for = id;
  const parts = [el('span', { className: 'field-label', textContent: label })];
  let range = null;
  const [smin, smax] = span ?? [min, max];
  if (slider && Number.isFinite(smin) && Number.isFinite(smax)) {
    // A log slider moves the exponent, 100 steps a decade.
    const [lo, hi] = log ? [Math.log10(smin), Math.log10(smax)] : [smin, smax];
    const toRange = (v) => (log ? Math.log10(v) : v);
    const fromRange = (r) => (log ? Number((10 ** r).toPrecision(3)) : r);
    const rangeStep = log ? 0.01 : step === 'any' ? (hi - lo) / 200 : step;
    range = el('input', { type: 'range', min: lo, max: hi, step: rangeStep, value: toRange(value) });
    range.dataset.testid = `${id}-slider`;
    range.setAttribute('aria-label', label);
    range.addEventListener('input', () => { input.value = fromRange(Number(range.value)); });
    range.addEventListener('change', () => { input.value = fromRange(Number(range.value)); commit(); });
    range.sync = (v) => { range.value = toRange(v); };
    parts.push(range);
  }
  const commit = () => {
    const text = input.value.trim();
    const v = text === '' ? null : Number(text);
    if (v !== null && !Number.isFinite(v)) { setError(msg, input, `${label} must be a number`); return; }
    if (range && v !== null && (!log || v > 0)) range.sync(v);
    onCommit(v, id);
  };
  input.addEventListener('change', commit);
  return el('label', { className: 'field' }, ...parts, input, msg);
}

function setError(msg, input, text) {
  msg.textContent = text;
  input?.classList.toggle('invalid', text !== '');
}

/** Shows `text` next to field `id` ('' clears it); returns false when there is no such field. */
export function showFieldError(box, id, text) {
  const msg = box.querySelector(`[data-for="${id}"]`);
  if (!msg) return false;
  setError(msg, box.querySelector(`[data-testid="${id}"]`), text);
  return true;
}

export function clearFieldErrors(box) {
  for (const m of box.querySelectorAll('.field-error')) m.textContent = '';
  for (const i of box.querySelectorAll('.invalid')) i.classList.remove('invalid');
}

/**
 * Rebuilds the parameter box for config `c`. `onChange(patch, fieldId)` receives a function
 * applying one field's new value to a config copy.
 */
export function buildFields(box, c, { catalog, torusParams, defaults, onChange }) {
  box.replaceChildren();
  if (c.scene === 'torus') {
    for (const [k, spec] of Object.entries(torusParams)) {
      box.append(numberField({
        id: `param-${k}`, label: spec.label, value: c.params[k],
        onCommit: (v, id) => onChange((n) => { n.params[k] = v ?? NaN; }, id),
      }));
    }
    return;
  }
  if (c.scene === IMPORTED) {
    const i = c.imported;
    // The selects show how the file is read (the worker's guess) until the user picks.
    const as = i.as ?? i.read?.as ?? 'surface';
    box.append(
      labelled('read as', choice('import-as', [['surface', 'surface (P-Hex)'], ['panels', 'panels (planarise)']], as,
        (v) => onChange((n) => { n.imported.as = v; }, 'import-as', true),
        'a NURBS surface or a triangle mesh of a smooth surface is panelled by P-Hex; quads, hexagons or any polygons are planarised')),
      labelled('unit', choice('import-unit', IMPORT_UNITS.map((u) => [u, u]), i.unit ?? i.read?.unit ?? 'm',
        (v) => onChange((n) => { n.imported.unit = v; }, 'import-unit'),
        'length unit of the file\'s coordinates (a .3dm or a NURBS JSON states its own; otherwise metres)')),
    );
    if (as === 'surface') {
      // The free mode's P-Hex fields, on the opened surface (sizes in the file's unit).
      runFields(box, i, (apply, id) => onChange((n) => apply(n.imported), id), defaults, 'in the file\'s unit');
    } else {
      box.append(
        labelled('panels', choice('import-mode', IMPORT_MODES.map((m) => [m, m]), i.mode,
          (v) => onChange((n) => { n.imported.mode = v; }, 'import-mode'), 'planarisation mode of a panel mesh')),
        checkbox('import-fix-boundary', 'fix boundary', i.fixBoundary, 'keep every boundary vertex exactly where the file puts it',
          (v) => onChange((n) => { n.imported.fixBoundary = v; }, 'import-fix-boundary')),
        numberField({
          id: 'import-closeness', label: 'closeness', value: i.closeness ?? 0.01, min: 1e-4, max: 1e3, slider: true, log: true,
          title: 'how strongly the vertices stay near the design (default 0.01; larger keeps them nearer, at more iterations)',
          onCommit: (v, id) => onChange((n) => { n.imported.closeness = v; }, id),
        }),
        numberField({
          id: 'import-tolerance-mm', label: 'tolerance mm', value: i.toleranceMm ?? '', min: 0,
          title: 'the largest distance of a panel corner from its plane, in mm (empty: planar to rounding, 1e-11 of an edge)',
          onCommit: (v, id) => onChange((n) => { n.imported.toleranceMm = v; }, id),
        }),
        anchorsField(i.anchors, () => onChange((n) => { n.imported.anchors = []; }, 'import-anchors', true)),
      );
    }
    return;
  }
  if (c.scene !== FREE) return;
  const surface = catalog.find((s) => s.name === c.free.surface);
  const pick = el('select', { title: surface?.parametrisation ?? '' });
  pick.dataset.testid = 'free-surface';
  pick.append(...catalog.map((s) => new Option(s.name, s.name)));
  pick.value = c.free.surface;
  pick.addEventListener('change', () => onChange((n) => {
    n.free.surface = pick.value;
    n.params = Object.fromEntries(catalog.find((s) => s.name === pick.value).params.map((p) => [p.key, p.default]));
  }, 'free-surface', true));
  box.append(labelled('surface', pick));
  const run = (apply, id) => onChange((n) => apply(n.free), id);
  runFields(box, c.free, run, defaults, null, () => {
    for (const p of surface?.params ?? []) {
      const { range, log } = sliderSpan(p);
      box.append(numberField({
        id: `param-${p.key}`, label: p.key, value: c.params[p.key], min: p.min, max: p.max,
        step: p.integer ? 1 : 'any', slider: true, range, log, title: `${p.doc} [${p.min}, ${p.max}]; the slider spans ${range[0]}..${range[1]}, type any value in range`,
        onCommit: (v, id) => onChange((n) => { n.params[p.key] = v ?? NaN; }, id),
      }));
    }
  });
}

/**
 * The slider of a surface parameter spans the values people use, not the whole range the core
 * accepts (1e-6..1e6 for a length would leave R = 2 at the far left): positive parameters over
 * four decades around the default on a log scale, others ten times the default either side;
 * integers their whole range. Typed values reach the rest.
 */
/** A small default as `1e-6` rather than `0.000001`, so that it fits its field. */
const compact = (x) => (x !== 0 && Math.abs(x) < 1e-3 ? x.toExponential() : String(x));

export function sliderSpan(p) {
  const clamp = (x) => Math.min(p.max, Math.max(p.min, x));
  if (p.integer) return { range: [p.min, p.max], log: false };
  const d = p.default;
  if (d > 0 && p.max > 0) {
    const lo = clamp(Math.max(d / 100, p.min > 0 ? p.min : d / 100));
    return { range: [lo, clamp(d * 100)], log: lo > 0 };
  }
  const w = d === 0 ? 1 : 10 * Math.abs(d);
  return { range: [clamp(d - w), clamp(d + w)], log: false };
}

/**
 * The free mode's P-Hex run fields (`free-method`, `free-init`, then `between()`'s fields, then
 * `free-size`, `free-bound`, `free-lambda`, `free-mu`) for the settings object `s`;
 * `onChange(apply, id)` with `apply(settings)` changing a copy. `unit` (or null) is said in the
 * size's tooltip.
 */
function runFields(box, s, onChange, defaults, unit, between = () => {}) {
  const method = choice('free-method', schema().methods.map((m) => [m.name, m.label]), s.method,
    (v) => onChange((t) => { t.method = v; }, 'free-method'),
    'P-Hex triangulation of section 5.2: progressive (method 1, from a base curve) or prescribed (method 2, along the parameter lines, which should be conjugate)');
  const init = choice('free-init', schema().initialisations.map((m) => [m.name, m.label]), s.init,
    (v) => onChange((t) => { t.init = v; }, 'free-init'),
    'hexagon initialisation: tangent duality (sec. 4.1, starts planar) or Dupin duality (sec. 6, the optimisation makes it planar)');
  box.append(labelled('method', method), labelled('init', init));
  between();
  const run = [
    ['size', 'panel size', `target edge length of the base curve${unit ? `, ${unit}` : ''} (empty: 1/48 of its length)`],
    ['bound', 'b', `parabolic lower bound b of section 5.3 (default ${defaults.bound})`],
    ['lambda', 'λ', `fairness weight of section 7 (default ${defaults.lambda})`],
    ['mu', 'μ', `surface-distance weight of section 7 (default ${defaults.mu})`],
  ];
  for (const [k, label, title] of run) {
    box.append(numberField({
      id: `free-${k}`, label, value: s[k] ?? (k === 'size' ? '' : compact(defaults[k])), title,
      onCommit: (v, id) => onChange((t) => { t[k] = v; }, id),
    }));
  }
}
