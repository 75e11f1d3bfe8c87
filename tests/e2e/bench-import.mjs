// Page figure for BENCHMARKS.md (not a test): P-Hex on an imported NURBS surface at 10k panels,
// in the page's worker. The design is the benchmarks' NURBS roof (`nurbs_roof` in dupin-core's
// `scenes::benchmark_meshes`, written out here: bicubic, 12 x 9 control points at the Greville
// points of z = 2 sin(x / 5) + 0.06 y², 20 m x 15 m), opened with the file input and panelled
// at size 0.22 m (10 203 faces), `runs` times (Reset, then Play).
//   DUPIN_URL=http://127.0.0.1:8094/ node tests/e2e/bench-import.mjs [runs] [reshapes]
// Prints per run: the worker's time summed over the run's states, split as `timing` splits it
// (solver, metrics, render buffers), its steps' time as `session.step()` measures it (solver and
// metrics, `ms`), and the wall time from Play to `done` (every state also drawn and posted).
// Then `reshapes` control-point drags (default 0): control point (6, 4) 8 px up, then back, in
// `moves` pointer moves (default 5) `gap` ms apart (default 40); per drag the positions the
// panelling followed (the hash's moves), the worker's time over the run the release leaves (the
// states of the last position sent) and the wall time from the release to its `done`.
//   DUPIN_URL=... node tests/e2e/bench-import.mjs 1 2 20 100   (a slow drag: 2 s)
import { byId, onScreen, openPage, waitDone } from './harness.mjs';

/** Control point (i, j) of the roof's net. */
function roofPoint(i, j) {
  return JSON.parse(roofJson()).control_points[i][j];
}

function roofJson() {
  const p = 3;
  const knots = (n) => {
    const spans = n - p;
    return [...Array(p + 1).fill(0), ...Array.from({ length: spans - 1 }, (_, i) => i + 1), ...Array(p + 1).fill(spans)];
  };
  const greville = (k, n) => Array.from({ length: n }, (_, i) => k.slice(i + 1, i + p + 1).reduce((a, b) => a + b, 0) / p / (n - p));
  const [nu, nv] = [12, 9];
  const [ku, kv] = [knots(nu), knots(nv)];
  const points = greville(ku, nu).map((a) => {
    const x = -10 + 20 * a;
    return greville(kv, nv).map((b) => {
      const y = -7.5 + 15 * b;
      return [x, y, 2 * Math.sin(x / 5) + 0.06 * y * y];
    });
  });
  return JSON.stringify({ degree_u: p, degree_v: p, knots_u: ku, knots_v: kv, control_points: points, unit: 'm' });
}

const runs = Number(process.argv[2] ?? 3);
const { browser, page } = await openPage();
try {
  await byId(page, 'import-file').setInputFiles({ name: 'roof.json', mimeType: 'application/json', buffer: Buffer.from(roofJson()) });
  await page.waitForFunction(() => document.querySelector('[data-testid=scene-select]').value === 'imported', null, { timeout: 60_000 });
  await byId(page, 'free-size').fill('0.22');
  await byId(page, 'free-size').press('Enter');
  await page.waitForFunction(() => /size=0\.22/.test(location.hash), null, { timeout: 60_000 });
  for (let r = 0; r < runs; r++) {
    if (r > 0) {
      await byId(page, 'reset').click();
      await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase !== 'done', null, { timeout: 60_000 });
    }
    const t0 = await page.evaluate(() => performance.now());
    await byId(page, 'play').click();
    await waitDone(page, 120_000);
    const r0 = await page.evaluate((since) => {
      const log = window.dupin.stepLog.filter((s) => s.at >= since);
      const sum = (f) => log.reduce((a, s) => a + (Number.isFinite(f(s)) ? f(s) : 0), 0);
      const last = log.at(-1);
      return {
        faces: last.faces,
        maxPlanarity: last.maxPlanarity,
        states: log.length,
        solveMs: Math.round(sum((s) => s.timing?.solve)),
        metricsMs: Math.round(sum((s) => s.timing?.metrics)),
        meshMs: Math.round(sum((s) => s.timing?.mesh)),
        stepMs: Math.round(sum((s) => s.ms)),
        wallMs: Math.round(last.at - since),
      };
    }, t0);
    const m = await page.evaluate(() => ({ ...document.querySelector('[data-testid=metrics]').dataset }));
    console.log(JSON.stringify({ run: r + 1, ...r0, invalidFaces: m.invalidFaces, phase: m.phase }));
  }
  const reshapes = Number(process.argv[3] ?? 0);
  const moves = Number(process.argv[4] ?? 5);
  const gap = Number(process.argv[5] ?? 40);
  if (reshapes > 0) {
    await byId(page, 'edit-vertices').click();
    await byId(page, 'control-net').waitFor({ state: 'visible', timeout: 5000 });
  }
  const [[x0, y0]] = await onScreen(page, [roofPoint(6, 4)]);
  for (let r = 0; r < reshapes; r++) {
    const [from, to] = r % 2 === 0 ? [y0, y0 - 8] : [y0 - 8, y0];
    await page.evaluate(() => {
      window.__up = null;
      document.querySelector('[data-testid=canvas]').addEventListener('pointerup', () => { window.__up = performance.now(); }, { once: true });
    });
    await page.mouse.move(x0, from);
    await page.mouse.down();
    for (let i = 1; i <= moves; i++) {
      await page.mouse.move(x0, from + ((to - from) * i) / moves);
      await page.waitForTimeout(gap);
    }
    await page.mouse.up();
    await page.waitForFunction(() => window.__up !== null && !window.dupin.dragPending && ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 120_000 });
    const d = await page.evaluate(() => {
      const log = window.dupin.stepLog.filter((s) => s.dragSeq === window.dupin.dragSeq);
      const sum = (f) => Math.round(log.reduce((a, s) => a + (Number.isFinite(f(s)) ? f(s) : 0), 0));
      const last = log.at(-1);
      return {
        states: log.length,
        workerMs: sum((s) => s.timing.solve + s.timing.metrics + s.timing.mesh),
        solveMs: sum((s) => s.timing.solve),
        afterReleaseMs: Math.round(Math.max(0, last.at - window.__up)),
        phase: last.phase,
        faces: last.faces,
        maxPlanarity: last.maxPlanarity,
        followed: new URLSearchParams(location.hash.slice(1)).get('cp').split(';').length,
      };
    });
    console.log(JSON.stringify({ reshape: r + 1, ...d }));
  }
} finally {
  await browser.close();
}
