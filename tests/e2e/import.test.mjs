// A user's own design in the page: a NURBS surface opened with the file input is panelled by
// P-Hex, a panel mesh dropped on the page is planarised, a broken file is refused with its name
// and line while the previous run stays, and a link to an imported design opened without the
// file says so. The files are made here, never downloaded.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, domeJson, exportText, metrics, objVertices, openPage, parseObj, pixelStats, shot, waitDone } from './harness.mjs';

/** A 10 x 10 quad grid over 20 m with seeded +-1 mm noise in z: panels that are nearly planar. */
function noisyGridObj() {
  let seed = 7;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  const n = 10;
  let obj = '';
  for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) obj += `v ${2 * i} ${2 * j} ${(rnd() - 0.5) * 0.002}\n`;
  const id = (i, j) => i * (n + 1) + j + 1;
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) obj += `f ${id(i, j)} ${id(i + 1, j)} ${id(i + 1, j + 1)} ${id(i, j + 1)}\n`;
  return obj;
}

/**
 * The noisy grid at 1.3 m spacing moved by `shift`: at state-plane coordinates (3e6, 5e6) its
 * vertices are 0.5 m apart in `f32`, so a view that drew them in absolute `f32` would snap them.
 */
function spacedGridObj(shift) {
  let seed = 7;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  const n = 10;
  let obj = '';
  for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) obj += `v ${1.3 * i + shift[0]} ${1.3 * j + shift[1]} ${(rnd() - 0.5) * 0.002 + shift[2]}\n`;
  const id = (i, j) => i * (n + 1) + j + 1;
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) obj += `f ${id(i, j)} ${id(i + 1, j)} ${id(i + 1, j + 1)} ${id(i, j + 1)}\n`;
  return obj;
}

async function play(page) {
  await byId(page, 'play').click();
  await page.waitForFunction(() => ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 180_000 });
}

test('open a NURBS design, panel it, export; drop a panel mesh and planarise it; refuse a broken file', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'import-file').setInputFiles({ name: 'dome.json', mimeType: 'application/json', buffer: Buffer.from(domeJson()) });
    await page.waitForFunction(() => document.querySelector('[data-testid=scene-select]').value === 'imported', null, { timeout: 60_000 });
    const option = await byId(page, 'scene-select').locator('option[value=imported]').textContent();
    assert.equal(option, 'imported: dome.json');
    const status = await byId(page, 'status').textContent();
    assert.match(status, /imported: dome\.json · surface · 12\.00 × 12\.00 × [0-9.]+ m \(unit m\)/);
    assert.match(page.url(), /scene=imported/);
    await play(page);
    let m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.equal(m.invalidFaces, '0');
    assert.ok(Number(m.maxPlanarity) <= 1e-10, m.maxPlanarity);
    assert.equal(parseObj(await exportText(page, 'export-obj')).faces, Number(m.faces));
    // The selects show how the file was read; the free mode's fields drive the opened surface.
    assert.equal(await byId(page, 'import-as').inputValue(), 'surface');
    assert.deepEqual(await byId(page, 'import-as').locator('option').evaluateAll((o) => o.map((x) => x.value)), ['surface', 'panels']);
    assert.equal(await byId(page, 'import-unit').inputValue(), 'm');
    assert.deepEqual(await byId(page, 'import-unit').locator('option').evaluateAll((o) => o.map((x) => x.value)), ['mm', 'cm', 'm', 'in', 'ft']);
    assert.equal(await byId(page, 'free-method').inputValue(), 'prescribed');
    // The fabrication pack, in the design's metres: DXF in millimetres with one closed polyline
    // a panel, a CSV row a panel, a GLB with its magic and version.
    const dxf = await exportText(page, 'export-dxf');
    assert.match(dxf, /\$INSUNITS\s+70\s+4/);
    const onPanels = dxf.split(/^LWPOLYLINE$/m).slice(1).filter((e) => /\n\s*8\nPANELS\n/.test(e.slice(0, 200)));
    assert.equal(onPanels.length, Number(m.faces));
    const csv = (await exportText(page, 'export-csv')).trim().split('\n');
    assert.equal(csv.length, Number(m.faces) + 1);
    const [download] = await Promise.all([page.waitForEvent('download'), byId(page, 'export-glb').click()]);
    assert.equal(download.suggestedFilename(), 'dome.glb');
    const glb = (await import('node:fs')).readFileSync(await download.path());
    assert.equal(glb.toString('latin1', 0, 4), 'glTF');
    assert.equal(glb.readUInt32LE(4), 2);
    assert.equal(glb.readUInt32LE(8), glb.length);

    // A larger panel size (free-size, in the file's metres) gives fewer panels.
    await byId(page, 'free-size').fill('1.2');
    await byId(page, 'free-size').press('Enter');
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    assert.match(page.url(), /size=1\.2/);
    await play(page);
    const coarse = await metrics(page);
    assert.equal(coarse.phase, 'done', await byId(page, 'status').textContent());
    assert.ok(Number(coarse.faces) < Number(m.faces) / 2, `${coarse.faces} vs ${m.faces}`);

    // A panel mesh dropped anywhere on the page: planarised, keeping the design.
    await page.evaluate((text) => {
      const dt = new DataTransfer();
      dt.items.add(new File([text], 'grid.obj'));
      document.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    }, noisyGridObj());
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('grid.obj · panels'), null, { timeout: 60_000 });
    assert.equal(await byId(page, 'scene-select').locator('option[value=imported]').textContent(), 'imported: grid.obj');
    await play(page);
    m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.ok(Number(m.maxPlanarity) <= 1e-9, m.maxPlanarity);
    // The design is kept: +-1 mm of noise moves the vertices by about that, never 2 mm.
    assert.ok(Number(m.maxDeviationMm) > 0.1 && Number(m.maxDeviationMm) <= 2, m.maxDeviationMm);
    assert.match(await byId(page, 'metrics').textContent(), /moved from design/);
    assert.equal(await byId(page, 'import-as').inputValue(), 'panels');
    // Fix the boundary: the run restarts with it and still ends planar.
    await byId(page, 'import-fix-boundary').check();
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    assert.match(page.url(), /fix=1/);
    await play(page);
    m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());

    // A broken file: its name and line in the status, the planarised grid stays.
    await byId(page, 'import-file').setInputFiles({ name: 'broken.json', mimeType: 'application/json', buffer: Buffer.from('{\n "degree_u": 3,\n "degree_v": x }') });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('broken.json: '), null, { timeout: 60_000 });
    assert.match(await byId(page, 'status').textContent(), /broken\.json: not a NURBS surface .*line 3/);
    assert.equal((await metrics(page)).faces, m.faces);
    assert.equal(await byId(page, 'scene-select').locator('option[value=imported]').textContent(), 'imported: grid.obj');

    // The design is kept in this browser (IndexedDB): a reload shows it again, as it was read.
    await page.reload();
    await page.waitForFunction(() => document.querySelector('[data-testid=scene-select] option[value=imported]')?.textContent === 'imported: grid.obj'
      && document.querySelector('[data-testid=metrics]').dataset.phase === 'done', null, { timeout: 60_000 });
    assert.equal(await byId(page, 'scene-select').inputValue(), 'imported');
    assert.equal((await metrics(page)).faces, m.faces);
    assert.equal(await byId(page, 'import-fix-boundary').isChecked(), true);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a link to an imported design opened without the file says so and the page stays usable', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=imported&as=panels' });
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('open it again'), null, { timeout: 60_000 });
    assert.equal(await byId(page, 'play').isDisabled(), true);
    await byId(page, 'scene-select').selectOption('sphere-radial');
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    assert.equal(await byId(page, 'play').isDisabled(), false);
    assert.doesNotMatch(await byId(page, 'status').textContent(), /open it again/);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a long read says how long it has taken and Stop cancels it, back to the previous run', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    const before = await metrics(page);
    // 320 000 triangles of a smooth bump: the fit takes seconds in the worker.
    const n = 400;
    const lines = [];
    for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) lines.push(`v ${i / 20} ${j / 20} ${Math.sin(i / 90) * Math.cos(j / 70)}`);
    const id = (i, j) => i * (n + 1) + j + 1;
    for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) lines.push(`f ${id(i, j)} ${id(i + 1, j)} ${id(i + 1, j + 1)}`, `f ${id(i, j)} ${id(i + 1, j + 1)} ${id(i, j + 1)}`);
    await byId(page, 'import-file').setInputFiles({ name: 'big.obj', mimeType: 'text/plain', buffer: Buffer.from(lines.join('\n')) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('Stop cancels'), null, { timeout: 60_000 });
    assert.match(await byId(page, 'status').textContent(), /reading big\.obj… \d+ s/);
    assert.equal(await byId(page, 'stop').isDisabled(), false);
    await byId(page, 'stop').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('cancelled'), null, { timeout: 60_000 });
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    assert.equal((await metrics(page)).faces, before.faces);
    assert.equal(await byId(page, 'scene-select').inputValue(), 'sphere-radial');
    assert.equal(await byId(page, 'scene-select').locator('option[value=imported]').count(), 0);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('panels: a click anchors a vertex, which stays exactly where the file puts it; closeness and a tolerance in mm', async () => {
  const { browser, page, errors } = await openPage();
  try {
    const text = noisyGridObj();
    const original = text.split('\n').filter((l) => l.startsWith('v ')).map((l) => l.split(' ').slice(1).map(Number));
    await byId(page, 'import-file').setInputFiles({ name: 'grid.obj', mimeType: 'text/plain', buffer: Buffer.from(text) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('grid.obj · panels'), null, { timeout: 60_000 });
    assert.equal(await byId(page, 'import-anchors').getAttribute('data-anchors'), '0');
    // Click vertex 60 (the middle of the grid) where the view draws it.
    const at = await page.evaluate(([x, y, z]) => {
      const q = window.dupin.viewer.project(x, y, z);
      const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      return { x: r.left + (q[0] + 1) / 2 * r.width, y: r.top + (1 - q[1]) / 2 * r.height };
    }, original[60]);
    await page.mouse.click(at.x, at.y);
    await page.waitForFunction(() => document.querySelector('[data-testid=import-anchors]')?.dataset.anchors === '1'
      && /anchors=60(&|$)/.test(location.hash), null, { timeout: 60_000 });
    await play(page);
    let m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    const out = (await exportText(page, 'export-obj')).split('\n').filter((l) => l.startsWith('v ')).map((l) => l.split(/\s+/).slice(1).map(Number));
    assert.deepEqual(out[60], original[60]);
    assert.ok(out.some((p, i) => p[2] !== original[i][2]), 'the other vertices moved');

    // A tolerance of 0.5 mm and a closeness of 10 (typed; the slider follows on a log scale).
    await byId(page, 'import-tolerance-mm').fill('0.5');
    await byId(page, 'import-tolerance-mm').press('Enter');
    await page.waitForFunction(() => /tol=0\.5/.test(location.hash), null, { timeout: 60_000 });
    await byId(page, 'import-closeness').fill('10');
    await byId(page, 'import-closeness').press('Enter');
    await page.waitForFunction(() => /closeness=10/.test(location.hash), null, { timeout: 60_000 });
    assert.equal(Number(await byId(page, 'import-closeness-slider').inputValue()), 1);
    await play(page);
    m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    // 0.5 mm on 2 m panels: planarity at most 2.5e-4 (the contract measure).
    assert.ok(Number(m.maxPlanarity) <= 0.5 / 2000, m.maxPlanarity);
    assert.match(page.url(), /anchors=60/);

    await byId(page, 'import-clear-anchors').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=import-anchors]')?.dataset.anchors === '0'
      && !/anchors=/.test(location.hash), null, { timeout: 60_000 });
    // Clearing the anchors is a change like any other: Undo brings the anchor back.
    await byId(page, 'undo').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=import-anchors]')?.dataset.anchors === '1'
      && /anchors=60(&|$)/.test(location.hash), null, { timeout: 60_000 });
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a design at state-plane coordinates is drawn as at zero, anchored where it is drawn, and exported where the file puts it', async () => {
  const { browser, page, errors } = await openPage();
  try {
    const open = async (name, text) => {
      await byId(page, 'import-file').setInputFiles({ name, mimeType: 'text/plain', buffer: Buffer.from(text) });
      await page.waitForFunction((n) => document.querySelector('[data-testid=status]').textContent.includes(`${n} · panels`), name, { timeout: 60_000 });
    };
    await open('near.obj', spacedGridObj([0, 0, 0]));
    const near = await shot(page, 'import-near-zero');
    // The view's origin for this design (metrics `viewOrigin`): its box centre, rounded to 16 m.
    const shift = [3e6, 5e6, 96];
    const text = spacedGridObj(shift);
    await open('far.obj', text);
    const far = await shot(page, 'import-state-plane');
    const s = await pixelStats(page, far, near);
    console.log(`# state-plane grid: covers ${s.covered.toFixed(3)} of the view, ${s.differing.toFixed(5)} of the pixels differ from it at zero`);
    assert.ok(s.covered > 0.05, `the design covers ${s.covered} of the view`);
    assert.ok(s.differing < 0.002, `${s.differing} of the pixels differ from the design drawn at zero`);
    // Click vertex 60 where the view draws it (relative to the view's origin).
    const original = objVertices(text);
    const at = await page.evaluate(([x, y, z]) => {
      const q = window.dupin.viewer.project(x, y, z);
      const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
      return { x: r.left + (q[0] + 1) / 2 * r.width, y: r.top + (1 - q[1]) / 2 * r.height };
    }, original[60].map((c, k) => c - shift[k]));
    await page.mouse.click(at.x, at.y);
    await page.waitForFunction(() => /anchors=60(&|$)/.test(location.hash), null, { timeout: 60_000 });
    await play(page);
    const m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.ok(Number(m.maxDeviationMm) <= 2, m.maxDeviationMm);
    const out = objVertices(await exportText(page, 'export-obj'));
    assert.deepEqual(out[60], original[60]);
    const off = Math.max(...out.map((p, i) => Math.hypot(...p.map((c, k) => c - original[i][k]))));
    assert.ok(off <= 2e-3, `a vertex moved ${off} m`);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a tube-like mesh (a vault closed around) is fitted closed and panelled all around', async () => {
  const { browser, page, errors } = await openPage();
  try {
    // 64 x 24 quads of a vault of revolution split into triangles: cylinder topology, no UVs.
    const [nu, nv] = [64, 24];
    let obj = '';
    for (let j = 0; j <= nv; j++) for (let i = 0; i < nu; i++) {
      const a = 2 * Math.PI * i / nu, z = 6 * j / nv, r = 3 + 0.4 * Math.cos(0.8 * z);
      obj += `v ${r * Math.cos(a)} ${r * Math.sin(a)} ${z}\n`;
    }
    const id = (i, j) => j * nu + (i % nu) + 1;
    for (let j = 0; j < nv; j++) for (let i = 0; i < nu; i++) obj += `f ${id(i, j)} ${id(i + 1, j)} ${id(i + 1, j + 1)}\nf ${id(i, j)} ${id(i + 1, j + 1)} ${id(i, j + 1)}\n`;
    await byId(page, 'import-file').setInputFiles({ name: 'vault.obj', mimeType: 'text/plain', buffer: Buffer.from(obj) });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('vault.obj · surface'), null, { timeout: 60_000 });
    await byId(page, 'free-size').fill('0.45');
    await byId(page, 'free-size').press('Enter');
    await page.waitForFunction(() => /size=0\.45/.test(location.hash), null, { timeout: 60_000 });
    await play(page);
    const m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.equal(m.invalidFaces, '0');
    assert.ok(Number(m.maxPlanarity) <= 1e-10, m.maxPlanarity);
    // All around with no seam: every panel edge away from the two loops is shared by two panels.
    const text = await exportText(page, 'export-obj');
    const { faces } = parseObj(text);
    assert.ok(faces > 300, `${faces} panels`);
    const v = objVertices(text);
    const f = text.split('\n').filter((l) => l.startsWith('f ')).map((l) => l.split(/\s+/).slice(1).map((x) => Number(x.split('/')[0]) - 1));
    const uses = new Map();
    for (const face of f) face.forEach((a, k) => { const b = face[(k + 1) % face.length]; const key = Math.min(a, b) + ',' + Math.max(a, b); uses.set(key, (uses.get(key) ?? 0) + 1); });
    const zs = v.map((p) => p[2]);
    const [lo, hi] = [Math.min(...zs), Math.max(...zs)];
    const open = [...uses].filter(([key, n]) => n === 1 && key.split(',').every((i) => v[i][2] > lo + 0.8 && v[i][2] < hi - 0.8));
    assert.deepEqual(open, [], 'boundary edges away from the loops (a seam)');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
