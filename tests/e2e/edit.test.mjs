// Drag to edit: in edit mode a drag on a panel mesh moves the vertex under the pointer, the
// solver keeps every panel planar while it moves, and the vertex ends under the pointer; Undo
// gives back the mesh before the drag and Redo the dragged one, both bit for bit.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, domeJson, dragImportedGrid, exportText, metrics, objVertices, onScreen, openImportedGrid, openPage, waitDone } from './harness.mjs';

// The drag, in pixels: about half an edge of the finished scene at the default view.
const DX = 10, DY = 6;

const edits = (page) => page.evaluate(() => new URLSearchParams(location.hash.slice(1)).get('edits'));

/** The last drag of an `edits` hash value: `{ v, group, path }`, its end the last of `path`. */
function lastEdit(text) {
  const [head, coords] = text.split(';').at(-1).split(':');
  const [v, ...group] = head.split('+').map(Number);
  return { v, group, path: coords.split('/').map((p) => p.split(',').map(Number)) };
}

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
      return !window.dupin.dragPending && d.phase === 'done' && Number(d.maxPlanarity) <= 1e-9 && location.hash.includes('edits=');
    }, null, { timeout: 60_000 });
    const settleMs = Date.now() - stop;
    const m = await metrics(page);
    console.log(`drag: ${states} states in ${tDrag.toFixed(2)} s (${(states / tDrag).toFixed(1)} per s); planar (${m.maxPlanarity}) ${settleMs} ms after the pointer stopped`);
    assert.ok(Number(m.maxPlanarity) <= 1e-9, m.maxPlanarity);
    assert.ok(states >= 3, `the mesh followed the drag (${states} states)`);

    // The dragged vertex is held where the pointer left it: its recorded position projects to
    // the pointer, and the OBJ has it there.
    const { v, path } = lastEdit(await edits(page));
    const xyz = path.at(-1);
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
    // Measured 53-100 ms (BENCHMARKS.md; the budget is 100 ms); a restart from the
    // drag's start took 0.8-1 s. Five times the budget leaves room for a busy machine.
    assert.ok(r.settle.ms <= 500, `planar ${r.settle.ms} ms after release`);
    const { v, path } = lastEdit(await edits(page));
    const xyz = path.at(-1);
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

test('a box-selected group of an opened quad mesh drags together: planar again, moved by one translation, undo bit for bit', async () => {
  const { browser, page, errors } = await openPage();
  try {
    const n = 32;
    await openImportedGrid(page, n);
    const before = await exportText(page, 'export-obj');
    const base = objVertices(before);
    const id = (i, j) => i * (n + 1) + j;
    const middle = id(n / 2, n / 2);
    const block = [];
    for (let i = n / 2 - 1; i <= n / 2 + 1; i++) for (let j = n / 2 - 1; j <= n / 2 + 1; j++) block.push(id(i, j));
    const screen = await onScreen(page, base);
    // A rectangle around the 3 x 3 block, a third of an edge (on screen) beyond it; the page
    // must select exactly the vertices whose projection lies inside.
    const edgePx = Math.hypot(screen[middle][0] - screen[id(n / 2 + 1, n / 2)][0], screen[middle][1] - screen[id(n / 2 + 1, n / 2)][1]);
    const xs = block.map((v) => screen[v][0]), ys = block.map((v) => screen[v][1]);
    const pad = edgePx / 3;
    const rect = [Math.min(...xs) - pad, Math.min(...ys) - pad, Math.max(...xs) + pad, Math.max(...ys) + pad];
    const inside = screen.flatMap((p, v) => (p && p[0] >= rect[0] && p[0] <= rect[2] && p[1] >= rect[1] && p[1] <= rect[3] ? [v] : []));
    assert.ok(block.every((v) => inside.includes(v)), 'the block is inside its rectangle');

    await byId(page, 'edit-vertices').click();
    await page.keyboard.down('Shift');
    await page.mouse.move(rect[0], rect[1]);
    await page.mouse.down();
    await page.mouse.move((rect[0] + rect[2]) / 2, (rect[1] + rect[3]) / 2, { steps: 3 });
    assert.ok(await byId(page, 'select-band').isVisible(), 'the rectangle is drawn while Shift-dragging');
    await page.mouse.move(rect[2], rect[3], { steps: 3 });
    await page.mouse.up();
    await page.keyboard.up('Shift');
    const hint = byId(page, 'selection');
    await page.waitForFunction((k) => document.querySelector('[data-testid=selection]').dataset.count === String(k), inside.length);
    console.log(`box selection: ${inside.length} vertices (${await hint.textContent()})`);
    assert.ok(await byId(page, 'selection-overlay').isVisible(), 'the selected vertices are marked');
    assert.ok(!(await byId(page, 'select-band').isVisible()), 'the rectangle goes on release');

    // Drag the middle vertex: the selection comes along.
    const [x0, y0] = screen[middle];
    const [dx, dy] = [12, -8];
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let i = 1; i <= 20; i++) {
      await page.mouse.move(x0 + (dx * i) / 20, y0 + (dy * i) / 20);
      await page.waitForTimeout(25);
    }
    await page.mouse.up();
    await page.waitForFunction(() => {
      const d = document.querySelector('[data-testid=metrics]').dataset;
      return !window.dupin.dragPending && d.phase === 'done' && Number(d.maxPlanarity) <= 1e-9 && location.hash.includes('edits=');
    }, null, { timeout: 120_000 });
    const m = await metrics(page);
    assert.ok(Number(m.maxPlanarity) <= 1e-9, m.maxPlanarity);
    const { v, group, path } = lastEdit(await edits(page));
    const xyz = path.at(-1);
    console.log(`group drag: ${path.length - 1} waypoints`);
    assert.equal(v, middle, 'the vertex under the pointer leads');
    assert.deepEqual(group, inside.filter((u) => u !== middle), 'the whole selection was dragged along');
    const [q] = await onScreen(page, [xyz]);
    assert.ok(Math.hypot(q[0] - (x0 + dx), q[1] - (y0 + dy)) < 1.5, `${q} vs pointer ${[x0 + dx, y0 + dy]}`);
    const after = await exportText(page, 'export-obj');
    const moved = objVertices(after);
    const delta = xyz.map((c, k) => c - base[middle][k]);
    const close = (a, b) => Math.abs(a - b) <= 1e-6 * (1 + Math.abs(b));
    for (const u of [v, ...group]) {
      assert.ok(moved[u].every((c, k) => close(c, base[u][k] + delta[k])), `vertex ${u}: ${moved[u]} vs ${base[u]} + ${delta}`);
    }
    // The rest made room: some vertex outside the selection moved.
    assert.ok(moved.some((p, u) => !inside.includes(u) && p.some((c, k) => c !== base[u][k])));

    await byId(page, 'undo').click();
    await page.waitForFunction(() => !location.hash.includes('edits='));
    await waitDone(page);
    assert.equal(await exportText(page, 'export-obj'), before, 'undo restores the mesh before the group drag');
    assert.ok(!(await hint.isVisible()), 'another run clears the selection');
    await byId(page, 'redo').click();
    await page.waitForFunction(() => location.hash.includes('edits='));
    await waitDone(page);
    assert.equal(await exportText(page, 'export-obj'), after, 'redo replays the group drag bit for bit');

    // Escape clears a selection.
    await page.keyboard.down('Shift');
    await page.mouse.move(rect[0], rect[1]);
    await page.mouse.down();
    await page.mouse.move(rect[2], rect[3], { steps: 4 });
    await page.mouse.up();
    await page.keyboard.up('Shift');
    await page.waitForFunction(() => Number(document.querySelector('[data-testid=selection]').dataset.count) > 0);
    await page.keyboard.press('Escape');
    await page.waitForFunction(() => document.querySelector('[data-testid=selection]').hidden);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('dragging a control point of an opened NURBS surface: the P-Hex panelling follows, the point under the pointer, undo bit for bit', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'import-file').setInputFiles({ name: 'dome.json', mimeType: 'application/json', buffer: Buffer.from(domeJson()) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('dome.json · surface'), null, { timeout: 120_000 });
    await byId(page, 'play').click();
    await waitDone(page, 300_000);
    const before = await exportText(page, 'export-obj');
    const button = byId(page, 'edit-vertices');
    assert.equal(await button.textContent(), 'Drag control points');
    await button.click();
    const overlay = byId(page, 'control-net');
    await overlay.waitFor({ state: 'visible', timeout: 5000 }); // edit mode draws the control net
    assert.equal(await overlay.getAttribute('data-points'), '36');

    // Control point (2, 2) of the 6 x 6 net: x = y = -1.2, z = 3 - 2.88 / 24.
    const index = 2 * 6 + 2;
    const [[x0, y0]] = await onScreen(page, [[-1.2, -1.2, 3 - 2.88 / 24]]);
    const [dx, dy] = [0, -14];
    const s0 = await page.evaluate(() => window.dupin.stepLog.length);
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) {
      await page.mouse.move(x0 + (dx * i) / 10, y0 + (dy * i) / 10);
      await page.waitForTimeout(40);
    }
    const states = (await page.evaluate(() => window.dupin.stepLog.length)) - s0;
    const t0 = Date.now();
    await page.mouse.up();
    await page.waitForFunction(() => location.hash.includes('cp='));
    await page.waitForFunction(() => !window.dupin.dragPending && ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 300_000 });
    const m = await metrics(page);
    const followed = await page.evaluate(() => new URLSearchParams(location.hash.slice(1)).get('cp').split(';').length);
    console.log(`control point drag: ${states} states while dragging, ${followed} positions followed; ${m.phase} ${Date.now() - t0} ms after release, ${m.faces} faces, max planarity ${m.maxPlanarity}, ${m.invalidFaces} invalid`);
    assert.ok(states >= 2, `the panelling followed the drag (${states} states)`);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.ok(Number(m.maxPlanarity) <= 1e-9, m.maxPlanarity);
    // The hash holds the positions the panelling followed, in order, the release's last.
    const cp = await page.evaluate(() => new URLSearchParams(location.hash.slice(1)).get('cp'));
    const moves = cp.split(';').map((e) => e.split(':'));
    assert.ok(moves.every(([head]) => Number(head) === index), cp);
    const coords = moves.at(-1)[1];
    const xyz = coords.split(',').map(Number);
    const [q] = await onScreen(page, [xyz]);
    assert.ok(Math.hypot(q[0] - (x0 + dx), q[1] - (y0 + dy)) < 1.5, `${q} vs pointer ${[x0 + dx, y0 + dy]}`);
    assert.ok(xyz[2] > 3 - 2.88 / 24, `dragged up: ${xyz}`);
    const after = await exportText(page, 'export-obj');
    assert.notEqual(after, before, 'the panelling follows the reshaped surface');

    await byId(page, 'undo').click();
    await page.waitForFunction(() => !location.hash.includes('cp='));
    await waitDone(page, 300_000);
    assert.equal(await exportText(page, 'export-obj'), before, 'undo restores the surface and its panels');
    await byId(page, 'redo').click();
    await page.waitForFunction(() => location.hash.includes('cp='));
    await waitDone(page, 300_000);
    assert.equal(await exportText(page, 'export-obj'), after, 'redo replays the reshaped surface bit for bit');
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
