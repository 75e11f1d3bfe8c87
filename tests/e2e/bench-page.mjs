// Page budget figures for BENCHMARKS.md (not a test): load to first frame, time per step in the
// worker for ~1k and ~10k faces, frame time while orbiting.
//   DUPIN_URL=http://127.0.0.1:8101/ node tests/e2e/bench-page.mjs
import { byId, openPage, waitDone, waitSteps } from './harness.mjs';

const median = (a) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.floor(s.length / 2)] : NaN; };
// Where a step's time goes: solver, metrics and render buffers in the worker, posting, and the
// page's handling of the state (buffers to the GPU, metrics panel).
const split = (log) => {
  const opt = log.filter((s) => (s.phase === 'optimisation' || s.phase === 'done') && s.timing);
  const r = {};
  for (const k of ['solve', 'metrics', 'mesh', 'prevPost']) r[k] = Math.round(10 * median(opt.map((s) => s.timing[k]))) / 10;
  r.main = Math.round(10 * median(opt.map((s) => s.mainMs))) / 10;
  return r;
};
const out = {};
for (const [backend, webgpu] of [['WebGPU', true], ['WebGL2', false]]) {
  const { browser, page } = await openPage({ webgpu });
  out[`${backend} first frame ms`] = Number(await page.evaluate(() => document.body.dataset.firstFrameMs));
  // Frame time while orbiting the 10k-face mesh: 60 drags, one rendered frame each.
  await page.goto(`${process.env.DUPIN_URL ?? 'http://127.0.0.1:8080/'}#scene=free&surface=torus&method=prescribed&size=0.155&init=dupin-duality${webgpu ? '' : '&backend=webgl2'}`);
  await page.waitForFunction(() => document.body.dataset.ready === 'true');
  await waitSteps(page, 1);
  if (webgpu) {
    await byId(page, 'play').click();
    await waitDone(page, 300_000);
    const log = await page.evaluate(() => window.dupin.stepLog.filter((s) => s.faces > 0));
    const opt = log.filter((s) => s.phase === 'optimisation' || s.phase === 'done').map((s) => s.ms);
    out['10k faces'] = log.at(-1).faces;
    out['10k optimisation step ms (median, all)'] = [median(opt), opt.map(Math.round)];
    out['10k split ms (median over optimisation steps)'] = split(log);
  }
  const frameMs = await page.evaluate(async () => {
    const c = document.querySelector('[data-testid=canvas]');
    const r = c.getBoundingClientRect();
    const times = [];
    let x = r.left + r.width / 2;
    c.dispatchEvent(new PointerEvent('pointerdown', { pointerId: 1, clientX: x, clientY: r.top + 100, bubbles: true }));
    for (let i = 0; i < 60; i++) {
      const t = performance.now();
      x += 3;
      c.dispatchEvent(new PointerEvent('pointermove', { pointerId: 1, clientX: x, clientY: r.top + 100, bubbles: true }));
      await new Promise((res) => requestAnimationFrame(() => requestAnimationFrame(res)));
      times.push((performance.now() - t) / 2);
    }
    c.dispatchEvent(new PointerEvent('pointerup', { pointerId: 1, bubbles: true }));
    return times;
  });
  out[`${backend} orbit frame ms (median), 10k hexagons`] = median(frameMs);
  if (webgpu) {
    await page.goto(`${process.env.DUPIN_URL ?? 'http://127.0.0.1:8080/'}#scene=free&surface=torus&method=prescribed&size=0.49&init=dupin-duality`);
    await page.waitForFunction(() => new URLSearchParams(location.hash.slice(1)).get('size') === '0.49');
    await waitSteps(page, 1);
    await page.evaluate(() => window.dupin.stepLog.splice(0));
    await byId(page, 'play').click();
    await waitDone(page);
    const log = await page.evaluate(() => window.dupin.stepLog);
    const opt = log.filter((s) => s.phase === 'optimisation' || s.phase === 'done').map((s) => s.ms);
    out['1k faces'] = log.at(-1).faces;
    out['1k optimisation step ms (median, all)'] = [median(opt), opt.map(Math.round)];
    out['1k split ms (median over optimisation steps)'] = split(log);
  }
  await browser.close();
}
console.log(JSON.stringify(out));
