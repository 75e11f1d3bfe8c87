// "Share presentation": ONE self-contained HTML file a client opens offline, from disk, with no
// server: the panels as glass in metal frames (the viewer-only wasm module, which carries the
// renderer and none of the solvers), the camera the design was shared from, and a quality
// certificate. Everything the file needs is inside it: the module's two builds (`pkg-viewer/`,
// WebGPU only, and `pkg-viewer-gl/`, with WebGL2 for browsers without WebGPU), each its
// wasm-bindgen glue and wasm, and the design, gzip-compressed and base64-encoded in inert
// <script> blocks; `presentation-viewer.js`, inlined as a classic script, runs the build the
// browser can draw with. Nothing is uploaded anywhere.

/** gzip (the browser's CompressionStream) then base64 of `bytes`. */
async function gzipBase64(bytes) {
  const gz = new Blob([bytes]).stream().pipeThrough(new CompressionStream('gzip'));
  const blob = await new Response(gz).blob();
  const url = await new Promise((resolve, reject) => {
    const r = new FileReader();
    r.onload = () => resolve(r.result);
    r.onerror = () => reject(r.error);
    r.readAsDataURL(blob);
  });
  return url.slice(url.indexOf(',') + 1);
}

async function fetchOk(path, as) {
  const r = await fetch(path);
  if (!r.ok) throw new Error(`${path}: HTTP ${r.status} (run \`cargo xtask build-web\`)`);
  return as === 'bytes' ? new Uint8Array(await r.arrayBuffer()) : r.text();
}

const escapeHtml = (s) => String(s).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
// Inlined scripts and JSON must not end their <script> element early.
const inlineScript = (s) => s.replace(/<\/(script)/gi, '<\\/$1');
const inlineJson = (v) => JSON.stringify(v).replace(/</g, '\\u003c');

const FACE_NAMES = { 3: 'triangles', 4: 'quads', 5: 'pentagons', 6: 'hexagons' };

/** Panel edge lengths and areas of `mesh` ({ vertices, faces }) times `scale` (metres per
 * model unit): { edges: [min, mean, max] m, areas: [min, max] m², sizes: { n: count } }. */
export function panelSizes(mesh, scale) {
  const v = mesh.vertices;
  let eMin = Infinity, eMax = 0, eSum = 0, eN = 0, aMin = Infinity, aMax = 0;
  const sizes = {};
  for (const f of mesh.faces) {
    sizes[f.length] = (sizes[f.length] ?? 0) + 1;
    // Newell's vector area: exact for a planar polygon, the projected area otherwise.
    let nx = 0, ny = 0, nz = 0;
    for (let i = 0; i < f.length; i++) {
      const a = v[f[i]], b = v[f[(i + 1) % f.length]];
      const e = Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]) * scale;
      eMin = Math.min(eMin, e); eMax = Math.max(eMax, e); eSum += e; eN++;
      nx += (a[1] - b[1]) * (a[2] + b[2]);
      ny += (a[2] - b[2]) * (a[0] + b[0]);
      nz += (a[0] - b[0]) * (a[1] + b[1]);
    }
    const area = 0.5 * Math.hypot(nx, ny, nz) * scale * scale;
    aMin = Math.min(aMin, area); aMax = Math.max(aMax, area);
  }
  return { edges: [eMin, eN ? eSum / eN : 0, eMax], areas: [aMin, aMax], sizes };
}

const mm = (m) => `${(m * 1000).toFixed(m * 1000 >= 100 ? 0 : 1)} mm`;
const fix3 = (x) => (x >= 10 ? x.toFixed(1) : x.toPrecision(3));

/** The quality certificate's rows ([label, text]) and state, from the page's JSON export
 * `doc` ({ mesh, metrics, report }), the layers on show (`layers`: { info: Session.layerInfo },
 * face distance in model units, or null), the page's panel edge (metres; a scene's scale),
 * the design's title and Dupin's version. */
export function certificate(doc, { layers, panelEdge, title, version, date = new Date() }) {
  const m = doc.metrics;
  // Metres per model unit: an opened design's own unit, a scene scaled to the page's panel edge.
  const edgeM = m.meanEdgeM ?? panelEdge;
  const scale = m.meanEdge > 0 ? edgeM / m.meanEdge : 1;
  const s = panelSizes(doc.mesh, scale);
  const count = doc.mesh.faces.length;
  const kinds = Object.entries(s.sizes).sort((a, b) => b[1] - a[1])
    .map(([n, c]) => `${c} ${FACE_NAMES[n] ?? `${n}-gons`}`).join(', ');
  const dims = (m.design?.dimensionsM ?? m.extent.map((x) => x * scale)).map(fix3).join(' × ');
  const warning = m.phase === 'warning' ? (m.reason ?? 'the result misses what was asked') : null;
  const rows = [
    ['design', title],
    ['panels', `${count} (${kinds})`],
    ['overall size', `${dims} m`],
    ['panel edges', `${mm(s.edges[0])} to ${mm(s.edges[2])}, mean ${mm(s.edges[1])}`],
    ['panel areas', `${fix3(s.areas[0])} to ${fix3(s.areas[1])} m²`],
    ['max planarity', `${(m.maxPlanarity * edgeM * 1000).toPrecision(3)} mm (${m.maxPlanarity.toExponential(1)} of a mean edge)`],
    ['invalid panels', String(m.invalidFaces ?? 0)],
  ];
  if (m.deviationMm) rows.push(['moved from design', `max ${m.deviationMm[0].toFixed(3)} mm, mean ${m.deviationMm[1].toFixed(3)} mm`]);
  if (m.conicalResidual !== undefined) rows.push(['conical residual', `${m.conicalResidual.toExponential(1)} rad`]);
  if (layers?.info) {
    const i = layers.info;
    rows.push(['offset', `${mm(Math.abs(i.distance) * scale)} face distance, ${i.offsetFaces} panels, planarity ${(i.offsetPlanarity * edgeM * 1000).toPrecision(3)} mm`]);
    rows.push(['support beams', `${i.beams}, planarity ${(i.beamPlanarity * edgeM * 1000).toPrecision(3)} mm`]);
  }
  rows.push(['status', warning ? `WARNING: ${warning}` : m.phase === 'done' ? 'finished' : `not finished (${m.phase})`]);
  rows.push(['computed', `${date.toISOString().slice(0, 10)} · Dupin ${version}`]);
  return { title, rows, warning, panels: count };
}

/**
 * The presentation file's text for the page's JSON export `exportText`, the view's `camera`
 * (six numbers) and the certificate's inputs (see `certificate`). Fetches the viewer-only
 * module and scripts from the page's own origin.
 */
export async function presentationFile(exportText, camera, options) {
  const doc = JSON.parse(exportText);
  const cert = certificate(doc, options);
  const [glue, glueGl, viewer, wasm, wasmGl] = await Promise.all([
    fetchOk('pkg-viewer/dupin_viewer.js', 'bytes'),
    fetchOk('pkg-viewer-gl/dupin_viewer.js', 'bytes'),
    fetchOk('presentation-viewer.js'),
    fetchOk('pkg-viewer/dupin_viewer_bg.wasm', 'bytes'),
    fetchOk('pkg-viewer-gl/dupin_viewer_bg.wasm', 'bytes'),
  ]);
  // Only what the viewer draws: the panels (full precision: the certificate is about them).
  const design = new TextEncoder().encode(JSON.stringify({ vertices: doc.mesh.vertices, faces: doc.mesh.faces }));
  const [designB64, glueB64, wasmB64, glueGlB64, wasmGlB64] = await Promise.all([design, glue, wasm, glueGl, wasmGl].map(gzipBase64));
  const title = escapeHtml(cert.title);
  return `<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="Dupin ${escapeHtml(options.version)}">
<title>${title} · Dupin presentation</title>
<style>
  html, body { margin: 0; height: 100%; background: #0b0c10; color: #e6e8ee; font: 14px system-ui, sans-serif; overflow: hidden; }
  canvas { position: fixed; inset: 0; width: 100%; height: 100%; display: block; touch-action: none; cursor: grab; }
  section { position: fixed; left: 16px; top: 16px; max-width: min(420px, calc(100% - 32px)); background: rgba(11, 12, 16, 0.82); border: 1px solid #2a2e3a; border-radius: 8px; padding: 12px 16px; }
  h1 { font-size: 17px; margin: 0 0 8px; }
  h2 { font-size: 12px; margin: 0 0 6px; color: #8d93a3; text-transform: uppercase; letter-spacing: 0.06em; font-weight: 600; }
  dl { display: grid; grid-template-columns: auto 1fr; gap: 3px 12px; margin: 0; }
  dt { color: #8d93a3; } dd { margin: 0; }
  [hidden] { display: none !important; }
  #full-screen { position: fixed; right: 16px; top: 16px; }
  button:focus-visible { outline: 2px solid #7aa2ff; outline-offset: 2px; }
  dd.warning, p.error { color: #ffb86b; font-weight: 600; }
  p { margin: 8px 0 0; color: #8d93a3; font-size: 12px; }
  #cert-toggle { position: absolute; right: 12px; top: 10px; padding: 2px 8px; font-size: 12px; }
  button { background: #1b1e27; color: #e6e8ee; border: 1px solid #2a2e3a; border-radius: 6px; padding: 6px 10px; font: inherit; cursor: pointer; }
</style>
</head>
<body data-state="loading">
<main>
<canvas id="view" data-testid="presentation-canvas" role="img" aria-label="${title}: ${cert.panels} planar panels in metal frames; drag to orbit, wheel to zoom"></canvas>
<section data-testid="certificate" aria-labelledby="cert-title">
<h2>Dupin quality certificate</h2>
<h1 id="cert-title">${title}</h1>
<button id="cert-toggle" type="button" aria-expanded="true" aria-controls="cert-rows">Hide figures</button>
<dl id="cert-rows"></dl>
<p data-testid="presentation-status" id="status" role="status">Loading…</p>
</section>
<button id="full-screen" type="button">Full screen</button>
</main>
<script type="application/json" id="dupin-certificate">${inlineJson(cert)}</script>
<script type="application/json" id="dupin-camera">${inlineJson(camera ?? null)}</script>
<script type="application/octet-stream" id="dupin-design">${designB64}</script>
<script type="application/octet-stream" id="dupin-glue">${glueB64}</script>
<script type="application/octet-stream" id="dupin-wasm">${wasmB64}</script>
<script type="application/octet-stream" id="dupin-glue-gl">${glueGlB64}</script>
<script type="application/octet-stream" id="dupin-wasm-gl">${wasmGlB64}</script>
<script>${inlineScript(viewer)}</script>
</body>
</html>
`;
}
