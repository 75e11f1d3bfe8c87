// The metrics panel: contract data attributes, a definition list, the planarity histogram (counts
// computed in Rust, drawn here as SVG) and the colour legend (stops from Rust's colorLegend).
const SVG = 'http://www.w3.org/2000/svg';
const svgEl = (tag, attrs) => {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  return e;
};

const exp = (x) => (x === 0 ? '0' : x.toExponential(2));
// Planarity as a person reads it: the corner distance in millimetres with three decimals (what a
// fabricator measures), the contract's relative figure (distance over mean edge) after it.
const mm = (rel, edge) => `${(rel * edge * 1000).toFixed(3)} mm`;
const planarity = (rel, edge) => `${mm(rel, edge)} · ${exp(rel)} of an edge`;

// Both writers below touch only what changed since the last call (cached per element): a step
// changes a few numbers, and rebuilding ~50 nodes per worker message cost style, layout and
// paint on a page thread that shares two cores with the worker and SwiftShader.
const panels = new WeakMap(); // dl -> { keys, dds }
const charts = new WeakMap(); // svg -> { shape, bars: [{ rect, title, c, h }] }

function setData(el, key, value) {
  if (value === undefined || value === null) {
    if (key in el.dataset) delete el.dataset[key];
  } else if (el.dataset[key] !== String(value)) {
    el.dataset[key] = String(value);
  }
}

function setText(node, text) {
  if (node.textContent !== text) node.textContent = text;
}

function setProp(node, key, value) {
  if (node[key] !== value) node[key] = value;
}

/** How many panels are not convex, and why that is no defect for P-Hex. */
function nonConvex(m) {
  const n = m.nonConvexFaces ?? 0;
  if (n === 0) return '0';
  const why = m.level === undefined
    ? 'where K < 0 a P-Hex hexagon is non-convex (P-Hex paper, sec. 4.2): planar and valid'
    : 'planar, but not convex';
  return `${n} of ${m.faces}: ${why}`;
}

/** The design's overall size in metres: an opened design's own, a scene's scaled so that its
 * mean edge is the page's panel edge (the scale every mm figure of a scene uses). */
function dimensions(m, panelEdge) {
  const m3 = (d) => d.map((x) => (x >= 10 ? x.toFixed(1) : x.toPrecision(2))).join(' × ');
  if (m.design?.dimensionsM) return `${m3(m.design.dimensionsM)} m`;
  if (!m.extent || !(m.meanEdge > 0)) return '–';
  return `${m3(m.extent.map((x) => (x * panelEdge) / m.meanEdge))} m at a ${panelEdge} m mean edge`;
}

/** Writes metrics `m` (from Session.step/metrics, plus `ms` and `steps`) into `dl`. */
export function showMetrics(dl, m, { panelEdge }) {
  // An opened design is measured in its own unit; a scene at the page's panel edge.
  const edge = m.meanEdgeM ?? panelEdge;
  const data = {
    phase: m.phase,
    layer: m.layer ?? 0,
    iteration: m.iteration,
    faces: m.faces,
    maxPlanarity: m.maxPlanarity,
    meanPlanarity: m.meanPlanarity ?? 0,
    invalidFaces: m.invalidFaces ?? 0,
    nonConvexFaces: m.nonConvexFaces ?? 0,
    steps: m.steps ?? 0,
    // PQ scenes: level and the scene's residuals (absent attributes for other runs).
    maxDeviationMm: m.deviationMm?.[0], meanDeviationMm: m.deviationMm?.[1],
    level: m.level, levels: m.levels, conicalResidual: m.conicalResidual, circularResidual: m.circularResidual, maxDeterminant: m.maxDeterminant, singularPointsInside: m.singularPointsInside,
  };
  for (const [k, v] of Object.entries(data)) setData(dl, k, v);
  // The torus preview is a smooth surface, not a run: no planarity figures to read.
  const rows = m.preview ? [
    ['showing', 'a smooth surface preview, no panels yet'],
    ['triangles', m.faces],
    ['vertices', m.vertices],
    ['next', 'pick a scene and press Play, or open your design'],
  ] : [
    ['phase', m.phase], ['layer', m.layer ?? 0], ['iteration', m.iteration], ['faces', m.faces],
    ['vertices', m.vertices],
    ['dimensions', dimensions(m, panelEdge)],
    ['max planarity', planarity(m.maxPlanarity, edge)],
    ['mean planarity', planarity(m.meanPlanarity ?? 0, edge)],
    ['invalid faces', m.invalidFaces ?? 0],
    ['non-convex panels', nonConvex(m)],
    ['step time', m.ms === undefined ? '–' : `${m.ms.toFixed(1)} ms`],
  ];
  if (m.level !== undefined && !m.preview) rows.splice(1, 1, ['level', `${m.level} of ${m.levels}`]);
  if (m.conicalResidual !== undefined) rows.push(['conical residual', `${exp(m.conicalResidual)} rad`]);
  if (m.circularResidual !== undefined) rows.push(['circular residual', exp(m.circularResidual)]);
  if (m.maxDeterminant !== undefined) rows.push(['max determinant', exp(m.maxDeterminant)]);
  if (m.singularPointsInside !== undefined) rows.push(['singular points on strip', m.singularPointsInside]);
  if (m.deviationMm) rows.push(['moved from design', `max ${m.deviationMm[0].toFixed(3)} mm · mean ${m.deviationMm[1].toFixed(3)} mm`]);
  const keys = rows.map(([k]) => k).join('|');
  let panel = panels.get(dl);
  if (panel?.keys !== keys || dl.children.length !== 2 * rows.length) {
    const dds = [];
    dl.replaceChildren(...rows.flatMap(([k]) => {
      const dt = document.createElement('dt'); dt.textContent = k;
      const dd = document.createElement('dd');
      dd.dataset.metric = k.replaceAll(' ', '-');
      dds.push(dd);
      return [dt, dd];
    }));
    panel = { keys, dds };
    panels.set(dl, panel);
  }
  rows.forEach(([, v], i) => setText(panel.dds[i], String(v)));
}

/** Bar chart of `m.histogram` over log10 planarity `m.histLog10`. */
export function drawHistogram(svg, m) {
  const counts = m.histogram ?? [];
  const [lo, hi] = m.histLog10 ?? [-16, -2];
  const W = 200, H = 60, max = Math.max(1, ...counts);
  setData(svg, 'total', counts.reduce((a, b) => a + b, 0));
  const bw = W / Math.max(1, counts.length);
  const shape = `${counts.length} ${lo} ${hi}`;
  let chart = charts.get(svg);
  if (chart?.shape !== shape || svg.children.length !== counts.length + 3) {
    svg.setAttribute('viewBox', `0 0 ${W} ${H + 12}`);
    const bars = counts.map((_, i) => {
      const rect = svgEl('rect', { x: i * bw + 0.5, y: H, width: bw - 1, height: 0, class: 'bar' });
      const title = svgEl('title', {});
      rect.append(title);
      return { rect, title, c: null, h: 0 };
    });
    svg.replaceChildren(
      ...bars.map((b) => b.rect),
      ...[lo, (lo + hi) / 2, hi].map((e, k) => {
        const t = svgEl('text', { x: (k * W) / 2, y: H + 10, 'text-anchor': ['start', 'middle', 'end'][k] });
        t.textContent = `1e${e}`;
        return t;
      }),
    );
    chart = { shape, bars };
    charts.set(svg, chart);
  }
  counts.forEach((c, i) => {
    const b = chart.bars[i];
    const h = c === 0 ? 0 : Math.max(1, (H * Math.log1p(c)) / Math.log1p(max));
    if (b.h !== h) {
      b.rect.setAttribute('y', String(H - h));
      b.rect.setAttribute('height', String(h));
      b.h = h;
    }
    if (b.c !== c) {
      b.title.textContent = `${c} faces with planarity in [1e${lo + i}, 1e${lo + i + 1})`;
      b.c = c;
    }
  });
}

/** Legend of a colour mode from its stops `[{label, color: [r, g, b] linear}]`. */
export function drawLegend(box, stops, caption = '') {
  const key = JSON.stringify([stops.map((s) => s.label), caption]);
  if (box.dataset.key === key) return;
  box.dataset.key = key;
  const srgb = (c) => Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055));
  const items = stops.map((s) => {
    const item = document.createElement('span');
    item.className = 'legend-item';
    const sw = document.createElement('i');
    sw.style.background = `rgb(${s.color.map(srgb).join(',')})`;
    item.append(sw, s.label);
    return item;
  });
  const note = document.createElement('span');
  note.className = 'legend-caption hint';
  note.dataset.testid = 'legend-caption';
  note.textContent = caption;
  box.replaceChildren(...items, ...(caption ? [note] : []));
}

/** What a colour mode's legend measures, in units: planarity relative to the mean edge, with
 * what one stop means in millimetres at an edge of `edgeM` metres. */
export function legendCaption(mode, edgeM) {
  if (mode === 'planarity') {
    const mm = 1e-6 * edgeM * 1000;
    return `corner distance from the panel's plane ÷ mean edge: at a ${Number(edgeM.toPrecision(3))} m edge, 1e-6 is ${Number(mm.toPrecision(3))} mm`;
  }
  if (mode === 'regularity') return 'shape deviation from the affine regular hexagon (P-Hex paper, sec. 4.2), relative';
  return 'panels by shape: a P-Hex hexagon is non-convex where K < 0 (sec. 4.2)';
}

/**
 * The progress bar of a run (`box` holds a <progress> and a text span): the share of steps done
 * under the core's upper bound on the steps left (`m.stepsLeftAtMost`; an iterative phase counts
 * its cap, so the bar may jump to the end when it converges early), and the time that bound takes
 * at the pace of `recentMs` (the last steps' worker times). Hidden when `show` is false.
 */
export function showProgress(box, m, { show, recentMs }) {
  const left = m.stepsLeftAtMost;
  const visible = show && Number.isFinite(left) && left > 0;
  setProp(box, 'hidden', !visible);
  if (!visible) return;
  const steps = m.steps ?? 0;
  const [bar, text] = box.children;
  setProp(bar, 'value', steps / (steps + left));
  const pace = recentMs.length ? recentMs.reduce((a, b) => a + b, 0) / recentMs.length : null;
  const eta = pace === null ? '' : ` · ${duration((pace * left) / 1000)} at the current pace`;
  setText(text, `step ${steps} · at most ${left} more${eta}`);
  setData(box, 'stepsLeft', left);
}

/** Seconds as a person reads them: "0.4 s", "12 s", "3 min 5 s". */
function duration(s) {
  if (s < 10) return `${s.toFixed(1)} s`;
  if (s < 60) return `${Math.round(s)} s`;
  return `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
}
