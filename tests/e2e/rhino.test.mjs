// Rhino .3dm in and out, and the fabrication pack read back by independent readers: a .3dm
// written here by rhino3dm (a NURBS roof as a single-face Brep, in millimetres) is dropped on the
// page, panelled, and exported as 3dm (read back by rhino3dm in Node), DXF (dxf-parser) and GLB
// (Khronos' glTF validator); a .3dm of quad panels in centimetres is planarised; a broken .3dm is
// refused with its name while the previous run stays.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import DxfParser from 'dxf-parser';
import validator from 'gltf-validator';
import rhino3dm from '../../web/vendor/node_modules/rhino3dm/rhino3dm.module.js';
import { byId, exportText, metrics, openPage, parseObj } from './harness.mjs';

const rhino = await rhino3dm();

/** A bicubic roof 12 m x 12 m in millimetres with conjugate parameter lines (heights f(x) + g(y)),
 * rational (weights 1 and 1.25) to exercise rhino3dm's homogeneous points, as a Brep face. */
function roof3dm() {
  const doc = new rhino.File3dm();
  doc.settings().modelUnitSystem = rhino.UnitSystem.Millimeters;
  const n = 6;
  const s = rhino.NurbsSurface.create(3, true, 4, 4, n, n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      const [x, y] = [2400 * i - 6000, 2400 * j - 6000];
      const w = (i + j) % 3 === 0 ? 1.25 : 1;
      const z = 3000 - (x * x + y * y) / 24000;
      s.points().set(i, j, [x * w, y * w, z * w, w]);
    }
  }
  // Rhino's knot convention: count + degree - 1 knots.
  const knots = [0, 0, 0, 1, 2, 3, 3, 3];
  knots.forEach((k, i) => { s.knotsU().set(i, k); s.knotsV().set(i, k); });
  const attributes = new rhino.ObjectAttributes();
  attributes.name = 'roof <b>&</b>';
  doc.objects().addBrep(rhino.Brep.createFromSurface(s), attributes);
  return Buffer.from(doc.toByteArray());
}

/** A 6 x 6 quad grid over 3 m in centimetres, noisy by +-0.1 cm, as one Rhino mesh. */
function grid3dm() {
  const doc = new rhino.File3dm();
  doc.settings().modelUnitSystem = rhino.UnitSystem.Centimeters;
  const m = new rhino.Mesh();
  const n = 6;
  let seed = 11;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) m.vertices().add(50 * i, 50 * j, (rnd() - 0.5) * 0.2);
  const id = (i, j) => i * (n + 1) + j;
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) m.faces().addQuadFace(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  doc.objects().addMesh(m, null);
  return Buffer.from(doc.toByteArray());
}

async function play(page) {
  await byId(page, 'play').click();
  await page.waitForFunction(() => ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 180_000 });
}

async function downloadBytes(page, id) {
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 60_000 }), byId(page, id).click()]);
  return { name: download.suggestedFilename(), bytes: readFileSync(await download.path()) };
}

const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

test('a Rhino roof in millimetres is panelled and leaves as 3dm, DXF and GLB that other readers read', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'import-file').setInputFiles({ name: 'roof.3dm', mimeType: 'application/octet-stream', buffer: roof3dm() });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('roof.3dm · surface'), null, { timeout: 90_000 });
    const status = await byId(page, 'status').textContent();
    // The file's unit is read: 12 000 mm are 12 m.
    assert.match(status, /imported: roof\.3dm · surface · 12\.00 × 12\.00 × [0-9.]+ m \(unit mm\)/);
    assert.match(status, /surface: roof <b>&<\/b>/); // the object's name, shown as text
    assert.equal(await page.locator('#status b').count(), 0);
    assert.equal(await byId(page, 'import-unit').inputValue(), 'mm');
    assert.equal(await byId(page, 'import-as').inputValue(), 'surface');
    await play(page);
    const m = await metrics(page);
    assert.equal(m.phase, 'done', await byId(page, 'status').textContent());
    assert.equal(m.invalidFaces, '0');
    assert.ok(Number(m.maxPlanarity) <= 1e-10, m.maxPlanarity);
    const faces = Number(m.faces);
    const obj = await exportText(page, 'export-obj');
    assert.equal(parseObj(obj).faces, faces);
    const vs = obj.split('\n').filter((l) => l.startsWith('v ')).map((l) => l.split(/\s+/).slice(1).map(Number));
    const fs = obj.split('\n').filter((l) => l.startsWith('f ')).map((l) => l.split(/\s+/).slice(1).map((t) => Number(t.split('/')[0]) - 1));

    // 3dm, read back by rhino3dm: millimetres, one planar surface a panel named by its number
    // on `Dupin panels` with the panel's edges, and its closed outline through the panel's
    // corners on `Dupin panel outlines`.
    const threeDm = await downloadBytes(page, 'export-3dm');
    assert.equal(threeDm.name, 'roof.3dm');
    const doc = rhino.File3dm.fromByteArray(new Uint8Array(threeDm.bytes));
    assert.ok(doc, 'rhino3dm reads the exported file');
    assert.equal(doc.settings().modelUnitSystem.value, rhino.UnitSystem.Millimeters.value);
    const layerName = (o) => doc.layers().get(o.attributes().layerIndex).name;
    const panels = [];
    const outlines = [];
    for (let i = 0; i < doc.objects().count; i++) {
      const o = doc.objects().get(i);
      if (layerName(o) === 'Dupin panels') panels.push(o);
      if (layerName(o) === 'Dupin panel outlines') outlines.push(o);
    }
    assert.equal(panels.length, faces);
    assert.equal(outlines.length, faces);
    const scale = Math.max(...vs.map((p) => Math.hypot(...p)));
    for (const [k, o] of panels.entries()) {
      assert.equal(o.attributes().name, String(k + 1));
      const corners = fs[k].map((v) => vs[v]);
      const brep = o.geometry();
      assert.equal(brep.constructor.name, 'Brep');
      assert.equal(brep.faces().count, 1);
      assert.ok(brep.faces().get(0).isPlanar(1e-9 * scale), `panel ${k + 1} is planar`);
      assert.equal(brep.edges().count, corners.length);
      const outline = outlines[k].geometry();
      assert.equal(outlines[k].attributes().name, String(k + 1));
      assert.ok(outline.isClosed, `outline ${k + 1} is closed`);
      assert.equal(outline.pointCount, corners.length + 1);
      for (let c = 0; c < corners.length; c++) assert.ok(dist(outline.point(c), corners[c]) <= 1e-12 * scale, `panel ${k + 1} corner ${c}`);
    }

    // DXF, read by dxf-parser: millimetres, a closed polyline a panel on PANELS, each panel's
    // flattened edges as long as its 3D edges (the design is in mm already).
    const dxf = new DxfParser().parseSync(await exportText(page, 'export-dxf'));
    assert.equal(dxf.header.$INSUNITS, 4);
    const polylines = dxf.entities.filter((e) => e.type === 'LWPOLYLINE' && e.layer === 'PANELS');
    assert.equal(polylines.length, faces);
    const labels = dxf.entities.filter((e) => e.type === 'TEXT' && e.layer === 'LABELS');
    assert.equal(labels.length, faces);
    for (const [k, p] of polylines.entries()) {
      assert.ok(p.shape, `panel ${k + 1} is closed`);
      const corners = fs[k].map((v) => vs[v]);
      assert.equal(p.vertices.length, corners.length);
      for (let c = 0; c < corners.length; c++) {
        const [a, b] = [p.vertices[c], p.vertices[(c + 1) % corners.length]];
        const flat = Math.hypot(a.x - b.x, a.y - b.y);
        const edge = dist(corners[c], corners[(c + 1) % corners.length]);
        assert.ok(Math.abs(flat - edge) <= 1e-9 * edge, `panel ${k + 1} edge ${c}: ${flat} vs ${edge}`);
      }
    }

    // GLB, checked by Khronos' validator: no errors, the panels' triangles.
    const glb = await downloadBytes(page, 'export-glb');
    const report = await validator.validateBytes(new Uint8Array(glb.bytes));
    assert.equal(report.issues.numErrors, 0, JSON.stringify(report.issues.messages.slice(0, 3)));
    assert.ok(report.info.totalTriangleCount >= faces, `${report.info.totalTriangleCount} triangles`);

    // A .3dm of quad panels in centimetres: planarised, in its unit.
    await byId(page, 'import-file').setInputFiles({ name: 'grid.3dm', mimeType: 'application/octet-stream', buffer: grid3dm() });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('grid.3dm · panels'), null, { timeout: 90_000 });
    assert.match(await byId(page, 'status').textContent(), /3\.00 × 3\.00 × [0-9.]+ m \(unit cm\)/);
    assert.equal(await byId(page, 'import-as').inputValue(), 'panels');
    assert.equal(await byId(page, 'import-unit').inputValue(), 'cm');
    // The design as read (+-1 mm of noise): its planarity in mm follows from its own 50 cm
    // panels, not from the page's 1.5 m panel edge.
    const g0 = await metrics(page);
    const shown = await page.locator('[data-metric="max-planarity"]').textContent();
    const mmShown = Number(shown.split(' mm')[0]);
    assert.ok(mmShown > 0.01 && Math.abs(mmShown - Number(g0.maxPlanarity) * 500) <= 0.0006, `${shown} vs ${g0.maxPlanarity}`);
    await play(page);
    const g = await metrics(page);
    assert.equal(g.phase, 'done', await byId(page, 'status').textContent());
    assert.equal(g.faces, '36');
    assert.ok(Number(g.maxPlanarity) <= 1e-9, g.maxPlanarity);
    assert.ok(Number(g.maxDeviationMm) <= 2, g.maxDeviationMm);


    // A broken .3dm: its name and what is wrong; the grid stays.
    await byId(page, 'import-file').setInputFiles({ name: 'broken.3dm', mimeType: 'application/octet-stream', buffer: Buffer.from('3D Geometry File Format, but cut short') });
    await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('broken.3dm: '), null, { timeout: 60_000 });
    assert.match(await byId(page, 'status').textContent(), /broken\.3dm: not a Rhino \.3dm file/);
    assert.equal((await metrics(page)).faces, '36');
    assert.equal(await byId(page, 'scene-select').locator('option[value=imported]').textContent(), 'imported: grid.3dm');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
