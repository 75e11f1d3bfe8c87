// The metrics panel: contract data attributes, a definition list, the planarity histogram (counts
// computed in Rust, drawn here as SVG) and the colour legend (stops from Rust's colorLegend).
const SVG = 'http://www.w3.org/2000/svg';
const svgEl = (tag, attrs) => {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  return e;
};

const exp = (x) => (x === 0 ? '0' : x.toExponential(2));
const mm = (rel, edge) => `${(rel * edge * 1000).toPrecision(3)} mm`;

/** Writes metrics `m` (from Session.step/metrics, plus `ms` and `steps`) into `dl`. */
export function showMetrics(dl, m, { panelEdge }) {
  Object.assign(dl.dataset, {
    phase: m.phase,
    layer: String(m.layer ?? 0),
    iteration: String(m.iteration),
    faces: String(m.faces),
    maxPlanarity: String(m.maxPlanarity),
    meanPlanarity: String(m.meanPlanarity ?? 0),
    invalidFaces: String(m.invalidFaces ?? 0),
    steps: String(m.steps ?? 0),
  });
  // PQ scenes: level and the scene's residuals (absent attributes for other runs).
  const extra = { level: m.level, levels: m.levels, conicalResidual: m.conicalResidual, circularResidual: m.circularResidual, maxDeterminant: m.maxDeterminant, singularPointsInside: m.singularPointsInside };
  for (const [k, v] of Object.entries(extra)) {
    if (v === undefined || v === null) delete dl.dataset[k];
    else dl.dataset[k] = String(v);
  }
  const rows = [
    ['phase', m.phase], ['layer', m.layer ?? 0], ['iteration', m.iteration], ['faces', m.faces],
    ['vertices', m.vertices],
    ['max planarity', `${exp(m.maxPlanarity)} · ${mm(m.maxPlanarity, panelEdge)}`],
    ['mean planarity', `${exp(m.meanPlanarity ?? 0)} · ${mm(m.meanPlanarity ?? 0, panelEdge)}`],
    ['invalid faces', m.invalidFaces ?? 0],
    ['step time', m.ms === undefined ? '–' : `${m.ms.toFixed(1)} ms`],
  ];
  if (m.level !== undefined) rows.splice(1, 1, ['level', `${m.level} of ${m.levels}`]);
  if (m.conicalResidual !== undefined) rows.push(['conical residual', `${exp(m.conicalResidual)} rad`]);
  if (m.circularResidual !== undefined) rows.push(['circular residual', exp(m.circularResidual)]);
  if (m.maxDeterminant !== undefined) rows.push(['max determinant', exp(m.maxDeterminant)]);
  if (m.singularPointsInside !== undefined) rows.push(['singular points on strip', m.singularPointsInside]);
  dl.replaceChildren(...rows.flatMap(([k, v]) => {
    const dt = document.createElement('dt'); dt.textContent = k;
    const dd = document.createElement('dd'); dd.textContent = String(v);
    dd.dataset.metric = k.replaceAll(' ', '-');
    return [dt, dd];
  }));
}

/** Bar chart of `m.histogram` over log10 planarity `m.histLog10`. */
export function drawHistogram(svg, m) {
  const counts = m.histogram ?? [];
  const [lo, hi] = m.histLog10 ?? [-16, -2];
  const W = 200, H = 60, max = Math.max(1, ...counts);
  svg.setAttribute('viewBox', `0 0 ${W} ${H + 12}`);
  svg.dataset.total = String(counts.reduce((a, b) => a + b, 0));
  const bw = W / Math.max(1, counts.length);
  svg.replaceChildren(
    ...counts.map((c, i) => {
      const h = c === 0 ? 0 : Math.max(1, (H * Math.log1p(c)) / Math.log1p(max));
      const r = svgEl('rect', { x: i * bw + 0.5, y: H - h, width: bw - 1, height: h, class: 'bar' });
      r.append(svgEl('title', {}));
      r.firstChild.textContent = `${c} faces with planarity in [1e${lo + i}, 1e${lo + i + 1})`;
      return r;
    }),
    ...[lo, (lo + hi) / 2, hi].map((e, k) => {
      const t = svgEl('text', { x: (k * W) / 2, y: H + 10, 'text-anchor': ['start', 'middle', 'end'][k] });
      t.textContent = `1e${e}`;
      return t;
    }),
  );
}

/** Legend of a colour mode from its stops `[{label, color: [r, g, b] linear}]`. */
export function drawLegend(box, stops) {
  const srgb = (c) => Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055));
  box.replaceChildren(...stops.map((s) => {
    const item = document.createElement('span');
    item.className = 'legend-item';
    const sw = document.createElement('i');
    sw.style.background = `rgb(${s.color.map(srgb).join(',')})`;
    item.append(sw, s.label);
    return item;
  }));
}
