// Share presentation: the page writes ONE HTML file that, opened from disk (file://) with the
// network off and every request outside the file refused, shows the panels (pixels that are not
// background) and a quality certificate whose figures are the page's.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, statSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { SHOTS, axeSerious, byId, gridObj, metrics, openPage, pixelStats, waitDone } from './harness.mjs';

/** Clicks Share and returns the written file's path and text. */
async function share(page) {
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 120_000 }), byId(page, 'share-presentation').click()]);
  // Saved under its own name (the browser opens a file by its extension), kept in target/e2e.
  const path = join(SHOTS, download.suggestedFilename());
  await download.saveAs(path);
  return { path, name: download.suggestedFilename(), text: readFileSync(path, 'utf8'), bytes: statSync(path).size };
}

/** Opens `path` from disk in a fresh, offline context of `browser` (with `webgpu: false`, one
 * that offers no `navigator.gpu`); returns the page, its certificate rows and the requests it
 * tried beyond the file itself. */
async function openOffline(browser, path, { webgpu = true } = {}) {
  const context = await browser.newContext({ viewport: { width: 960, height: 640 } });
  await context.setOffline(true);
  if (!webgpu) {
    await context.addInitScript(() => {
      Object.defineProperty(Navigator.prototype, 'gpu', { get: () => undefined, configurable: true });
      delete Navigator.prototype.gpu;
    });
  }
  const outside = [];
  await context.route('**/*', (route) => {
    const u = route.request().url();
    if (u.startsWith('file:')) return route.continue();
    outside.push(u);
    return route.abort();
  });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(pathToFileURL(path).href);
  await page.waitForFunction(() => document.body.dataset.state !== 'loading', null, { timeout: 60_000 });
  const state = await page.evaluate(() => document.body.dataset.state);
  const status = await byId(page, 'presentation-status').textContent();
  assert.equal(state, 'ready', status);
  console.log(`${path.split('/').pop()}: ready ${await page.evaluate(() => document.body.dataset.readyMs)} ms after navigation (${status})`);
  const rows = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll('[data-testid=certificate] dd')].map((d) => [d.dataset.row, d.textContent])));
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const url = await page.evaluate(() => window.dupinPresentation.snapshotDataUrl(1));
  const png = Buffer.from(url.slice(url.indexOf(',') + 1), 'base64');
  writeFileSync(`${path}.png`, png);
  await page.screenshot({ path: `${path}.page.png` });
  const px = await pixelStats(page, png);
  return { context, page, rows, status, outside, errors, px };
}

test('a shared presentation of conical-station opens offline from disk with its panels and certificate', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=conical-station' });
  try {
    await byId(page, 'play').click();
    await waitDone(page);
    await byId(page, 'toggle-offset').check();
    await page.waitForFunction(() => document.querySelector('[data-testid=layer-info]').dataset.beamPlanarity !== undefined);
    const m = await metrics(page);
    const file = await share(page);
    assert.equal(file.name, 'conical-station-presentation.html');
    assert.ok(!/<(script|img|iframe)[^>]+src=|<link[^>]+href=/i.test(file.text), 'the file loads nothing beside itself');
    const v = await openOffline(browser, file.path);
    assert.deepEqual(v.outside, [], 'no request leaves the file');
    assert.deepEqual(v.errors, []);
    assert.ok(v.px.covered > 0.05, `the design is drawn: ${JSON.stringify(v.px)}`);
    assert.match(v.rows.panels, new RegExp(`^${m.faces} \\(${m.faces} quads\\)`));
    // Planarity in mm at the page's 1.5 m panel edge, as the metrics panel states it.
    const mm = Number(v.rows['max-planarity'].split(' ')[0]);
    assert.ok(Math.abs(mm - m.maxPlanarity * 1.5 * 1000) <= 1e-3 * Math.max(mm, 1e-12) + 1e-15, `${v.rows['max-planarity']} vs ${m.maxPlanarity}`);
    assert.equal(v.rows.status, 'finished');
    assert.match(v.rows['support-beams'], /^\d+, planarity /);
    assert.match(v.rows.computed, /^\d{4}-\d\d-\d\d · Dupin \d+\.\d+\.\d+$/);
    assert.match(v.status, /panels · \d+ beams · WebGPU$/);
    assert.deepEqual(await axeSerious(v.page, 'shared presentation'), []);
    // The figures fold away and come back; the title stays.
    const toggle = v.page.locator('#cert-toggle');
    await toggle.click();
    assert.equal(await toggle.getAttribute('aria-expanded'), 'false');
    assert.ok(!(await v.page.locator('#cert-rows').isVisible()));
    assert.ok(await v.page.locator('h1').isVisible());
    await toggle.click();
    assert.ok(await v.page.locator('#cert-rows').isVisible());
    await v.context.close();
    // A browser without WebGPU runs the file's WebGL2 build of the viewer.
    const gl = await openOffline(browser, file.path, { webgpu: false });
    assert.deepEqual([gl.outside, gl.errors], [[], []]);
    assert.match(gl.status, /panels · \d+ beams · WebGL2$/);
    assert.ok(gl.px.covered > 0.05, `the design is drawn with WebGL2: ${JSON.stringify(gl.px)}`);
    await gl.context.close();
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a presentation of an opened 10 000-panel design stays within 3 MB and opens offline', async () => {
  const { browser, page, errors } = await openPage();
  try {
    // A name with markup in it: shown as text, never as HTML.
    await byId(page, 'import-file').setInputFiles({ name: 'roof <i>&.obj', mimeType: 'text/plain', buffer: Buffer.from(gridObj(100)) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('roof <i>&.obj · panels'), null, { timeout: 120_000 });
    await byId(page, 'play').click();
    await waitDone(page, 300_000);
    const t0 = Date.now();
    const file = await share(page);
    const seconds = (Date.now() - t0) / 1000;
    console.log(`presentation of 10 000 panels: ${(file.bytes / 1e6).toFixed(2)} MB, written in ${seconds.toFixed(2)} s`);
    assert.ok(file.bytes <= 3e6, `${file.bytes} bytes`);
    const v = await openOffline(browser, file.path);
    assert.deepEqual(v.outside, []);
    assert.deepEqual(v.errors, []);
    assert.ok(v.px.covered > 0.05, JSON.stringify(v.px));
    assert.match(v.rows.panels, /^10000 \(10000 quads\)/);
    assert.match(v.rows['moved-from-design'], /^max \d/);
    assert.equal(v.rows.design, 'roof <i>&');
    assert.equal(await v.page.locator('h1').textContent(), 'roof <i>&');
    assert.equal(await v.page.locator('i').count(), 0);
    assert.equal(await v.page.title(), 'roof <i>& · Dupin presentation');
    await v.context.close();
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('the certificate states a warning loudly and measures panels in real units', async () => {
  const { certificate, panelSizes } = await import('../../web/share.js');
  // A 2 x 1 model-unit quad and a unit triangle; 2 m per model unit.
  const mesh = { vertices: [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [0, 0, 1]], faces: [[0, 1, 2, 3], [0, 1, 4]] };
  const s = panelSizes(mesh, 2);
  assert.deepEqual(s.sizes, { 3: 1, 4: 1 });
  assert.equal(s.edges[0], 2);
  assert.ok(Math.abs(s.edges[2] - 2 * Math.hypot(2, 1)) < 1e-12);
  assert.ok(Math.abs(s.areas[1] - 8) < 1e-12 && Math.abs(s.areas[0] - 4) < 1e-12, String(s.areas));
  const metrics = { phase: 'warning', reason: '3 invalid faces', maxPlanarity: 1e-3, invalidFaces: 3, extent: [2, 1, 1], meanEdge: 1.5, meanEdgeM: 3 };
  const c = certificate({ mesh, metrics }, { layers: null, panelEdge: 1.5, title: '<b>roof</b>', version: '0.1.0', date: new Date('2026-12-05T12:00:00Z') });
  const rows = Object.fromEntries(c.rows);
  assert.equal(c.warning, '3 invalid faces');
  assert.equal(rows.status, 'WARNING: 3 invalid faces');
  assert.equal(rows['overall size'], '4.00 × 2.00 × 2.00 m');
  assert.equal(rows['max planarity'], '3.00 mm (1.0e-3 of a mean edge)');
  assert.equal(rows.computed, '2026-12-05 · Dupin 0.1.0');
  // Names are data: the viewer writes rows as text, and the file escapes the title.
  assert.equal(rows.design, '<b>roof</b>');
  const done = certificate({ mesh, metrics: { ...metrics, phase: 'done', reason: undefined } }, { layers: null, panelEdge: 1.5, title: 'x', version: '0.1.0' });
  assert.equal(Object.fromEntries(done.rows).status, 'finished');
  assert.equal(done.warning, null);
});
