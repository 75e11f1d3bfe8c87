// PQ step times in the page for BENCHMARKS.md (not a test): every PQ scene played level by
// level in the worker; per scene the step count and the median and largest worker step
// (`session.step()`: solver + metrics) by phase, and the render-buffer time with the offset and
// support layers on (conical-station).
//   DUPIN_URL=http://127.0.0.1:8101/ node tests/e2e/bench-pq.mjs
import { byId, openPage, waitDone, waitSteps } from './harness.mjs';

const median = (a) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.floor(s.length / 2)] : NaN; };
const r1 = (x) => Math.round(10 * x) / 10;
const PQ = ['pq-catmull-clark', 'conical-station', 'developable-trefoil', 'developable-strips', 'circular-principal'];
const out = {};
for (const scene of PQ) {
  // A fresh page per scene, opened at the scene's first step (with both layers for the station).
  const layers = scene === 'conical-station' ? '&offset=1&support=1' : '';
  const { browser, page } = await openPage({ hash: `#scene=${scene}&steps=1${layers}` });
  await waitSteps(page, 1);
  await byId(page, 'play').click();
  await waitDone(page);
  const log = (await page.evaluate(() => window.dupin.stepLog)).filter((s) => s.timing);
  const by = (p) => log.filter((s) => s.phase === p).map((s) => s.ms);
  const perturb = [...by('perturb'), ...by('done')];
  out[scene] = {
    steps: log.at(-1).steps,
    faces: log.at(-1).faces,
    perturbMs: { median: r1(median(perturb)), max: r1(Math.max(...perturb)) },
    subdivideMs: { median: r1(median(by('subdivide'))), max: r1(Math.max(...by('subdivide'))) },
    meshMs: r1(median(log.map((s) => s.timing.mesh))),
    mainMs: r1(median(log.map((s) => s.mainMs))),
  };
  await browser.close();
}
console.log(JSON.stringify(out));
