// Presentation mode in headless Chromium: glass and frames drawn (pixels from the GPU readback),
// a drag orbits, the 2x PNG has twice the size, the offset layer toggles, and the frame time
// while orbiting 10k panels is measured on both backends (SwiftShader: a software rasteriser, far
// slower than a GPU browser) through the page's readout and written to target/e2e/.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { SHOTS, byId, exportText, openPage, pixelStats } from './harness.mjs';

async function presentShot(page, name, scale = 1) {
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const url = await page.evaluate((s) => window.dupinPresent.snapshotDataUrl(s), scale);
  const png = Buffer.from(url.slice(url.indexOf(',') + 1), 'base64');
  writeFileSync(`${SHOTS}/${name}.png`, png);
  return png;
}

for (const [backend, webgpu] of [['WebGPU', true], ['WebGL2', false]]) {
  test(`${backend}: presentation mode draws glass in frames, orbits, exports a 2x PNG`, async () => {
    // The page's default torus preview: its triangles become the panels.
    const { browser, page, errors } = await openPage({ webgpu });
    try {
      await byId(page, 'present').click();
      const status = byId(page, 'present-status');
      await page.waitForFunction(() => document.querySelector('[data-testid="present-status"]').dataset.rendered === 'true', null, { timeout: 60_000 });
      assert.match(await status.textContent(), new RegExp(backend));
      const faces = Number(await byId(page, 'metrics').getAttribute('data-faces'));
      assert.equal(Number(await status.getAttribute('data-panels')), faces);
      const a = await presentShot(page, `present-${backend.toLowerCase()}`);
      const { covered } = await pixelStats(page, a);
      assert.ok(covered > 0.1, `only ${(covered * 100).toFixed(1)}% covered`);
      // Drag: the view turns and keeps coasting a little (damped orbit).
      const box = await byId(page, 'present-canvas').boundingBox();
      const [x, y] = [box.x + box.width / 2, box.y + box.height / 2];
      await page.mouse.move(x, y);
      await page.mouse.down();
      for (let i = 1; i <= 8; i++) await page.mouse.move(x + 15 * i, y + 3 * i);
      await page.mouse.up();
      const b = await presentShot(page, `present-${backend.toLowerCase()}-orbited`);
      assert.ok((await pixelStats(page, b, a)).differing > 0.01, 'orbit changed the view');
      // The 2x PNG.
      const [w, h] = await page.evaluate(() => window.dupinPresent.size());
      const big = await presentShot(page, `present-${backend.toLowerCase()}@2x`, 2);
      const dims = await page.evaluate(async (b64) => {
        const img = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
        return [img.width, img.height];
      }, big.toString('base64'));
      assert.deepEqual(dims, [2 * w, 2 * h]);
      // Offset layer: a triangle mesh has no conical vertices, so the core may refuse; either way the
      // page says what happened and keeps drawing.
      await byId(page, 'present-offset').check();
      const text = await status.textContent();
      if (/no offset layer/.test(text)) assert.ok(await status.evaluate((e) => e.classList.contains('error')));
      else assert.equal(Number(await status.getAttribute('data-panels')), 2 * faces);
      await byId(page, 'present-close').click();
      assert.ok(await byId(page, 'present-panel').isHidden());
      assert.deepEqual(errors, [], 'console errors');
    } finally {
      await browser.close();
    }
  });
}

// Frame time while orbiting the 10k-panel demo, on both backends: the page's own readout
// (`data-frame-ms` etc. on the canvas) over 30 orbit frames driven by its frame loop. Results go
// to target/e2e/present-frame-time-<backend>.json.
for (const [backend, webgpu] of [['WebGPU', true], ['WebGL2', false]]) {
  test(`${backend}: frame time while orbiting 10k panels (headless SwiftShader)`, async () => {
    const { browser, page } = await openPage({ webgpu });
    try {
      await byId(page, 'present').click();
      await byId(page, 'present-demo').click();
      const status = byId(page, 'present-status');
      await page.waitForFunction(() => Number(document.querySelector('[data-testid="present-status"]').dataset.panels) >= 10000, null, { timeout: 60_000 });
      const shot = await presentShot(page, `present-10k-${backend.toLowerCase()}`);
      assert.ok((await pixelStats(page, shot)).covered > 0.1);
      const r = await page.evaluate(() => window.dupinPresent.orbitFrames(30));
      r.panels = Number(await status.getAttribute('data-panels'));
      r.backend = (await status.textContent()).split(' ')[0];
      assert.equal(r.backend, backend);
      // The readout the user sees: the canvas attributes and the bar's text.
      const canvas = byId(page, 'present-canvas');
      const frameMs = Number(await canvas.getAttribute('data-frame-ms'));
      assert.ok(frameMs > 0 && Number.isFinite(frameMs), `data-frame-ms ${frameMs}`);
      assert.equal(frameMs, r.meanIntervalMs);
      assert.ok(Math.abs(Number(await canvas.getAttribute('data-fps')) - 1000 / frameMs) < 0.1);
      assert.ok(Number(await canvas.getAttribute('data-render-ms')) >= 0);
      assert.match(await byId(page, 'present-frame').textContent(), /ms\/frame · \d+ fps/);
      writeFileSync(`${SHOTS}/present-frame-time-${backend.toLowerCase()}.json`, JSON.stringify(r, null, 1));
      console.log('presentation frame time', r);
    } finally {
      await browser.close();
    }
  });
}

test('presentation frames panels, not triangles: counts are panels and beams follow panel edges', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=pq-catmull-clark' });
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    await byId(page, 'play').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done', null, { timeout: 120_000 });
    const obj = await exportText(page, 'export-obj');
    const faces = obj.split('\n').filter((l) => l.startsWith('f ')).map((l) => l.split(/\s+/).slice(1).map(Number));
    const edges = new Set();
    for (const f of faces) f.forEach((v, i) => { const w = f[(i + 1) % f.length]; edges.add(v < w ? `${v},${w}` : `${w},${v}`); });
    await byId(page, 'present').click();
    const status = byId(page, 'present-status');
    await page.waitForFunction(() => document.querySelector('[data-testid="present-status"]').dataset.rendered === 'true', null, { timeout: 60_000 });
    assert.equal(Number(await status.getAttribute('data-panels')), faces.length);
    assert.match(await status.textContent(), new RegExp(`${faces.length} panels · ${edges.size} beams`));
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
