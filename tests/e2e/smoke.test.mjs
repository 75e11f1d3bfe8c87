// The smoke test: the page starts, draws, runs a scene to the end, exports, and opens a Rhino
// file (rhino3dm loads from the page's own folder). `cargo xtask test` also runs it against
// `cargo xtask dist`'s folder served by a plain static file server (Python's http.server).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import rhino3dm from '../../web/vendor/node_modules/rhino3dm/rhino3dm.module.js';
import { byId, exportText, metrics, openPage, parseObj } from './harness.mjs';

test('smoke: start, run a scene to the end, export, open a .3dm', async () => {
  const { browser, page, errors, wasm } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    assert.match(await byId(page, 'status').textContent(), /^WebGPU/);
    // One module for the page and its worker: the WebGPU-only build (no WebGL2 backend).
    assert.deepEqual([...new Set(wasm)], ['pkg/dupin_web_bg.wasm']);
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    await byId(page, 'play').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done', null, { timeout: 120_000 });
    const m = await metrics(page);
    // Planarity as people read it: millimetres with three decimals, then the relative figure.
    assert.match(await page.locator('[data-metric="max-planarity"]').textContent(), /^\d+\.\d{3} mm · (0|\d\.\d{2}e[-+]\d+) of an edge$/);
    assert.equal(parseObj(await exportText(page, 'export-obj')).faces, Number(m.faces));

    const rhino = await rhino3dm();
    const doc = new rhino.File3dm();
    doc.settings().modelUnitSystem = rhino.UnitSystem.Meters;
    const mesh = new rhino.Mesh();
    for (const [x, y] of [[0, 0], [1, 0], [1, 1], [0, 1]]) mesh.vertices().add(x, y, 0);
    mesh.faces().addQuadFace(0, 1, 2, 3);
    doc.objects().addMesh(mesh, null);
    await byId(page, 'import-file').setInputFiles({ name: 'quad.3dm', mimeType: 'application/octet-stream', buffer: Buffer.from(doc.toByteArray()) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('quad.3dm · panels'), null, { timeout: 90_000 });
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
