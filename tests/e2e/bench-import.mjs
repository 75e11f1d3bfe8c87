// Page figure for BENCHMARKS.md (not a test): P-Hex on an imported NURBS surface at 10k panels,
// in the page's worker. The design is the benchmarks' NURBS roof (`nurbs_roof` in dupin-core's
// `scenes::benchmark_meshes`, written out here: bicubic, 12 x 9 control points at the Greville
// points of z = 2 sin(x / 5) + 0.06 y², 20 m x 15 m), opened with the file input and panelled
// at size 0.22 m (10 203 faces), `runs` times (Reset, then Play).
//   DUPIN_URL=http://127.0.0.1:8094/ node tests/e2e/bench-import.mjs [runs]
// Prints per run: the worker's time summed over the run's states, split as `timing` splits it
// (solver, metrics, render buffers), its steps' time as `session.step()` measures it (solver and
// metrics, `ms`), and the wall time from Play to `done` (every state also drawn and posted).
import { byId, openPage, waitDone } from './harness.mjs';

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
} finally {
  await browser.close();
}
