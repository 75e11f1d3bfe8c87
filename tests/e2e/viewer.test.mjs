// <dupin-viewer>: a design embedded in another page with one element (web/viewer-example.html):
// it draws the panels, orbits on drag, reports its state, and says what is wrong with a bad file.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, openPage, pixelStats } from './harness.mjs';

test('<dupin-viewer> shows an embedded design, orbits on drag and names a bad file\'s fault', async () => {
  const { browser, page, errors, wasm } = await openPage({ hash: 'viewer-example.html', ready: false });
  try {
    const viewer = byId(page, 'viewer');
    await page.waitForFunction(() => document.querySelector('dupin-viewer').dataset.state === 'ready', null, { timeout: 60_000 });
    const note = () => viewer.evaluate((v) => v.shadowRoot.querySelector('p').textContent);
    assert.match(await note(), /^384 panels · WebGPU$/);
    assert.deepEqual(wasm, ['pkg-viewer/dupin_viewer_bg.wasm']);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const first = await viewer.screenshot({ path: `${SHOTS}/viewer-example.png` });
    const { covered } = await pixelStats(page, first);
    assert.ok(covered > 0.05, `only ${(covered * 100).toFixed(1)}% of the element shows the design`);
    const box = await viewer.boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    for (let i = 1; i <= 8; i++) await page.mouse.move(box.x + box.width / 2 + 15 * i, box.y + box.height / 2 + 3 * i);
    await page.mouse.up();
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const second = await viewer.screenshot();
    assert.ok((await pixelStats(page, first, second)).differing > 0.01, 'a drag did not orbit');
    // A file that is not a design, then one that is missing: said inside the element, as events.
    await page.route('**/examples/not-a-design.json', (r) => r.fulfill({ body: '{"config": {}}', contentType: 'application/json' }));
    const failed = page.evaluate(() => new Promise((r) => document.querySelector('dupin-viewer').addEventListener('error', (e) => r(e.detail.message), { once: true })));
    await viewer.evaluate((v) => v.setAttribute('src', 'examples/not-a-design.json'));
    assert.match(await failed, /not a Dupin design: no `mesh`/);
    assert.equal(await viewer.getAttribute('data-state'), 'error');
    assert.match(await note(), /no `mesh`/);
    await viewer.evaluate((v) => v.setAttribute('src', 'examples/missing.json'));
    await page.waitForFunction(() => /HTTP 404/.test(document.querySelector('dupin-viewer').shadowRoot.querySelector('p').textContent));
    // And back to a good file.
    const loaded = page.evaluate(() => new Promise((r) => document.querySelector('dupin-viewer').addEventListener('load', (e) => r(e.detail), { once: true })));
    await viewer.evaluate((v) => v.setAttribute('src', 'examples/conical-station.json'));
    assert.equal((await loaded).faces, 384);
    assert.deepEqual(errors.filter((e) => !/404/.test(e)), []);
  } finally {
    await browser.close();
  }
});

test('<dupin-viewer> without WebGPU loads the WebGL2 build of the viewer and draws', async () => {
  const { browser, page, errors, wasm } = await openPage({ webgpu: false, hash: 'viewer-example.html', ready: false });
  try {
    const viewer = byId(page, 'viewer');
    await page.waitForFunction(() => document.querySelector('dupin-viewer').dataset.state === 'ready', null, { timeout: 60_000 });
    assert.equal(await viewer.evaluate((v) => v.shadowRoot.querySelector('p').textContent), '384 panels · WebGL2');
    assert.deepEqual(wasm, ['pkg-viewer-gl/dupin_viewer_bg.wasm']);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const { covered } = await pixelStats(page, await viewer.screenshot({ path: `${SHOTS}/viewer-example-webgl2.png` }));
    assert.ok(covered > 0.05, `only ${(covered * 100).toFixed(1)}% of the element shows the design`);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
