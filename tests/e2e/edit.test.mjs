// Drag to edit: in edit mode a drag on a panel mesh moves the vertex under the pointer, the
// solver keeps every panel planar while it moves, and the vertex ends under the pointer; Undo
// gives back the mesh before the drag and Redo the dragged one, both bit for bit.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, dragImportedGrid, exportText, metrics, openPage, waitDone } from './harness.mjs';

// The drag, in pixels: about half an edge of the finished scene at the default view.
const DX = 10, DY = 6;

const edits = (page) => page.evaluate(() => new URLSearchParams(location.hash.slice(1)).get('edits'));

test('dragging a vertex of conical-station keeps the panels planar, holds the vertex under the pointer, and undoes bit for bit', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=conical-station' });
  try {
    await byId(page, 'play').click();
    await waitDone(page);
    const before = await exportText(page, 'export-obj');
    const button = byId(page, 'edit-vertices');
    assert.ok(await button.isVisible(), 'a panel mesh offers dragging');
    await button.click();
    assert.equal(await button.getAttribute('aria-pressed'), 'true');

    const box = await byId(page, 'canvas').boundingBox();
    const x0 = box.x + box.width / 2, y0 = box.y + box.height / 2;
    const states0 = await page.evaluate(() => window.dupin.stepLog.length);
    const t0 = Date.now();
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    const moves = 20;
    for (let i = 1; i <= moves; i++) {
      await page.mouse.move(x0 + (DX * i) / moves, y0 - (DY * i) / moves);
      await page.waitForTimeout(25);
    }
    const tDrag = (Date.now() - t0) / 1000;
    const states = (await page.evaluate(() => window.dupin.stepLog.length)) - states0;
    const stop = Date.now();
    await page.mouse.up();
    // Planar again after the pointer stops.
    await page.waitForFunction(() => {
      const d = document.querySelector('[data-testid=metrics]').dataset;
      return d.phase === 'done' && Number(d.maxPlanarity) <= 1e-9 && location.hash.includes('edits=');
    }, null, { timeout: 60_000 });
    const settleMs = Date.now() - stop;
    const m = await metrics(page);
    console.log(`drag: ${states} states in ${tDrag.toFixed(2)} s (${(states / tDrag).toFixed(1)} per s); planar (${m.maxPlanarity}) ${settleMs} ms after the pointer stopped`);
    assert.ok(Number(m.maxPlanarity) <= 1e-9, m.maxPlanarity);
    assert.ok(states >= 3, `the mesh followed the drag (${states} states)`);

    // The dragged vertex is held where the pointer left it: its recorded position projects to
    // the pointer, and the OBJ has it there.
    const [v, ...xyz] = (await edits(page)).split(/[:,]/).map(Number);
    const onScreen = await page.evaluate(([px, py, pz]) => {
      const p = window.dupin.viewer.project(px, py, pz);
      const c = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      return [c.left + (p[0] + 1) * 0.5 * c.width, c.top + (1 - p[1]) * 0.5 * c.height];
    }, xyz);
    assert.ok(Math.hypot(onScreen[0] - (x0 + DX), onScreen[1] - (y0 - DY)) < 1.5, `vertex ${v} at ${onScreen}, pointer at ${[x0 + DX, y0 - DY]}`);
    const after = await exportText(page, 'export-obj');
    const line = after.split('\n').filter((l) => l.startsWith('v '))[v].split(' ').slice(1).map(Number);
    for (let k = 0; k < 3; k++) assert.ok(Math.abs(line[k] - xyz[k]) <= 1e-6 * (1 + Math.abs(xyz[k])), `OBJ ${line} vs ${xyz}`);
    assert.notEqual(after, before);

    // Undo: the mesh before the drag, bit for bit; Redo: the dragged one, replayed bit for bit.
    await byId(page, 'undo').click();
    await page.waitForFunction(() => !location.hash.includes('edits='));
    await waitDone(page);
    assert.equal(await exportText(page, 'export-obj'), before, 'undo restores the mesh before the drag');
    await byId(page, 'redo').click();
    await page.waitForFunction(() => location.hash.includes('edits='));
    await waitDone(page);
    assert.equal(await exportText(page, 'export-obj'), after, 'redo replays the drag to the same mesh');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('dragging a vertex of an opened 1 024-quad mesh: planar again, the vertex under the pointer, undo bit for bit', async () => {
  const { browser, page, errors } = await openPage();
  try {
    const r = await dragImportedGrid(page, 32);
    console.log(`imported 32 x 32: ${r.perSecond.toFixed(1)} states/s while dragging; ${r.settle.phase} at max planarity ${r.settle.maxPlanarity} ${r.settle.ms.toFixed(0)} ms after release`);
    assert.equal(r.settle.phase, 'done');
    assert.ok(r.settle.maxPlanarity <= 1e-9, r.settle.maxPlanarity);
    const [v, ...xyz] = (await edits(page)).split(/[:,]/).map(Number);
    assert.equal(v, r.middle, 'the vertex under the pointer was dragged');
    const q = await page.evaluate(([x, y, z]) => {
      const p = window.dupin.viewer.project(x, y, z);
      const c = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      return [c.left + (p[0] + 1) * 0.5 * c.width, c.top + (1 - p[1]) * 0.5 * c.height];
    }, xyz);
    assert.ok(Math.hypot(q[0] - r.pointer[0], q[1] - r.pointer[1]) < 1.5, `${q} vs ${r.pointer}`);
    const after = await exportText(page, 'export-obj');
    await byId(page, 'undo').click();
    await page.waitForFunction(() => !location.hash.includes('edits='));
    await waitDone(page);
    const before = await exportText(page, 'export-obj');
    assert.notEqual(before, after);
    await byId(page, 'redo').click();
    await page.waitForFunction(() => location.hash.includes('edits='));
    await waitDone(page);
    assert.equal(await exportText(page, 'export-obj'), after, 'redo replays the drag bit for bit');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a P-Hex run offers no dragging', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1');
    assert.ok(!(await byId(page, 'edit-vertices').isVisible()));
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
