// The teaching inset (P-Hex paper sections 3-5.1): it opens, draws, and reacts to a drag of a star
// vertex (its pixels and its Proposition 4 verdict change); the section 5.1 steps and bad input;
// a click on a mesh vertex in the 3D view opens it at that vertex's real star.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, drag, exportText, openPage, pixelStats, waitSteps } from './harness.mjs';

/** Screen position of a star handle (or the star centre for index -1). */
async function handle(page, i) {
  return page.evaluate((i) => {
    const svg = document.querySelector('[data-testid="teach-inset"]');
    const g = svg.querySelector('g');
    const m = g.getScreenCTM();
    if (i < 0) { const p = new DOMPoint(0, 0).matrixTransform(m); return [p.x, p.y]; }
    const c = svg.querySelector(`[data-vertex="${i}"]`);
    const p = new DOMPoint(Number(c.getAttribute('cx')), Number(c.getAttribute('cy'))).matrixTransform(m);
    return [p.x, p.y];
  }, i);
}

test('teach inset: a drag across line DE flips the verdict and redraws the inset', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'teach').click();
    const inset = byId(page, 'teach-inset');
    await inset.waitFor();
    const verdict = byId(page, 'teach-verdict');
    assert.equal(await verdict.getAttribute('data-kind'), 'elliptic');
    assert.equal(await verdict.getAttribute('data-verdict'), 'valid');
    const before = await inset.screenshot({ path: `${SHOTS}/teach-valid.png` });
    assert.ok((await pixelStats(page, before)).covered > 0.03, 'the inset draws something');
    const textBefore = await verdict.textContent();
    // Drag the apex b towards the base: 0.3 of the way from M (midpoint of 0a) keeps it below the
    // line DE of section 5.1, where Proposition 4 says the star is invalid.
    const [c, a, b] = [await handle(page, -1), await handle(page, 0), await handle(page, 1)];
    const m = [(c[0] + a[0]) / 2, (c[1] + a[1]) / 2];
    const to = [m[0] + 0.3 * (b[0] - m[0]), m[1] + 0.3 * (b[1] - m[1])];
    await page.mouse.move(b[0], b[1]);
    await page.mouse.down();
    for (let k = 1; k <= 8; k++) await page.mouse.move(b[0] + ((to[0] - b[0]) * k) / 8, b[1] + ((to[1] - b[1]) * k) / 8);
    await page.mouse.up();
    assert.equal(await verdict.getAttribute('data-verdict'), 'invalid');
    assert.notEqual(await verdict.textContent(), textBefore);
    assert.match(await byId(page, 'teach-reason').textContent(), /Proposition 4/);
    const after = await inset.screenshot({ path: `${SHOTS}/teach-invalid.png` });
    const { differing } = await pixelStats(page, after, before);
    assert.ok(differing > 0.005, `the drag changed only ${(differing * 100).toFixed(2)}% of the inset`);
    // The section 5.1 construction, step by step (five steps, then back to the plain view).
    const caption = byId(page, 'teach-caption');
    const seen = new Set();
    for (let k = 0; k < 5; k++) {
      await byId(page, 'teach-step').click();
      seen.add(await caption.textContent());
    }
    assert.equal(seen.size, 5);
    assert.match([...seen].join(' '), /5\.1/);
    await inset.screenshot({ path: `${SHOTS}/teach-ideal-steps.png` });
    await byId(page, 'teach-ideal').click();
    assert.equal(await verdict.getAttribute('data-verdict'), 'valid');
    assert.deepEqual(errors, [], 'console errors');
  } finally {
    await browser.close();
  }
});

test('teach inset: hyperbolic point (Proposition 5) and bad input shown inline', async () => {
  const { browser, page } = await openPage();
  try {
    await byId(page, 'teach').click();
    await byId(page, 'teach-v').fill('3.1');
    await byId(page, 'teach-v').dispatchEvent('change');
    const verdict = byId(page, 'teach-verdict');
    assert.equal(await verdict.getAttribute('data-kind'), 'hyperbolic');
    assert.equal(await verdict.getAttribute('data-verdict'), 'valid');
    assert.match(await byId(page, 'teach-reason').textContent(), /Proposition 5/);
    await byId(page, 'teach-inset').screenshot({ path: `${SHOTS}/teach-hyperbolic.png` });
    await byId(page, 'teach-u').fill('');
    await byId(page, 'teach-u').dispatchEvent('change');
    assert.match(await byId(page, 'teach-error').textContent(), /number/);
    await byId(page, 'teach-surface').selectOption('cylinder');
    await byId(page, 'teach-u').fill('0.2');
    await byId(page, 'teach-u').dispatchEvent('change');
    assert.equal(await verdict.getAttribute('data-kind'), 'parabolic');
    await byId(page, 'teach-step').click();
    assert.match(await byId(page, 'teach-error').textContent(), /K = 0|5\.3/);
    // The page stays usable.
    assert.equal(await byId(page, 'step').count(), 1);
  } finally {
    await browser.close();
  }
});

/** Vertices and faces of OBJ text. */
function parseObjFull(text) {
  const v = [], f = [];
  for (const l of text.split('\n')) {
    const p = l.trim().split(/\s+/);
    if (p[0] === 'v') v.push(p.slice(1, 4).map(Number));
    else if (p[0] === 'f') f.push(p.slice(1).map((s) => Number(s.split('/')[0]) - 1));
  }
  return { v, f };
}

/** Canvas pixel (page coordinates) of the 3D point `p` in the current view, with its depth. */
async function screenOf(page, p) {
  return page.evaluate(([x, y, z]) => {
    const q = window.dupin.viewer.project(x, y, z);
    if (!q) return null;
    const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    return { x: r.left + (q[0] + 1) / 2 * r.width, y: r.top + (1 - q[1]) / 2 * r.height, ndc: [q[0], q[1]], depth: q[2] };
  }, p);
}

const picked = (page) => byId(page, 'teach-inset').getAttribute('data-picked-vertex');

test('teach inset from a clicked 3D vertex: its real star, a boundary message, dragging still works', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=free&surface=torus&method=prescribed&size=0.5' });
  try {
    await waitSteps(page, 1);
    await byId(page, 'step').click();
    await waitSteps(page, 2);
    // Step 2 shows the base curve and one layer of triangles: every vertex is on the boundary.
    let mesh = parseObjFull(await exportText(page, 'export-obj'));
    // Click a triangle's centroid (inside the strip even after rounding to pixels).
    let s = null;
    for (const f of mesh.f) {
      const c = [0, 1, 2].map((d) => f.reduce((acc, i) => acc + mesh.v[i][d], 0) / f.length);
      const q = await screenOf(page, c);
      if (q && q.ndc[0] > 0.1 && q.ndc[0] < 0.9 && Math.abs(q.ndc[1]) < 0.9) { s = q; break; }
    }
    assert.ok(s, 'a triangle of the first layer in view');
    await page.mouse.click(s.x, s.y);
    await page.waitForFunction(() => /boundary/.test(document.querySelector('[data-testid=teach-error]').textContent));
    assert.equal(await byId(page, 'teach-panel').isHidden(), false, 'the inset opens');
    // Layers until all are shown (the mesh on screen is then the whole triangulation).
    const phase = () => page.evaluate(() => document.querySelector('[data-testid=metrics]').dataset.phase);
    for (let n = 3; (await phase()) !== 'hexagons'; n++) {
      await byId(page, 'step').click();
      await waitSteps(page, n);
    }
    mesh = parseObjFull(await exportText(page, 'export-obj'));
    assert.ok(mesh.f.every((f) => f.length === 3), 'the triangulation is on screen');
    // Interior valence-6 vertices (six triangles around them) and their neighbour sets.
    const around = mesh.v.map(() => []);
    for (const f of mesh.f) for (const i of f) around[i].push(f);
    const nbrs = (i) => [...new Set(around[i].flat().filter((j) => j !== i))].sort((a, b) => a - b);
    // The vertex nearest the eye among those projecting right of the inset (x > 0 in NDC).
    let best = null;
    for (let i = 0; i < mesh.v.length; i++) {
      if (around[i].length !== 6 || nbrs(i).length !== 6) continue;
      const q = await screenOf(page, mesh.v[i]);
      if (!q || q.ndc[0] < 0.1 || q.ndc[0] > 0.8 || Math.abs(q.ndc[1]) > 0.7) continue;
      if (!best || q.depth < best.q.depth) best = { i, q };
    }
    assert.ok(best, 'an interior vertex in view');
    await page.mouse.click(best.q.x, best.q.y);
    await page.waitForFunction((i) => document.querySelector('[data-testid=teach-inset]').dataset.pickedVertex === String(i), best.i);
    const inset = byId(page, 'teach-inset');
    // The controls show where the lesson is: the run's surface at the vertex's (u, v).
    assert.equal(await byId(page, 'teach-surface').inputValue(), 'torus');
    const [pu, pv] = (await byId(page, 'teach-source').textContent()).match(/\(u, v\) = \(([-0-9.]+), ([-0-9.]+)\)/).slice(1).map(Number);
    assert.ok(Math.abs(Number(await byId(page, 'teach-u').inputValue()) - pu) < 1e-3);
    assert.ok(Math.abs(Number(await byId(page, 'teach-v').inputValue()) - pv) < 1e-3);
    const got = (await inset.getAttribute('data-picked-neighbours')).split(',').map(Number);
    assert.deepEqual([...got].sort((a, b) => a - b), nbrs(best.i), 'the star is the vertex\'s six neighbours');
    // Counter-clockwise ring: consecutive neighbours span a triangle of the vertex.
    for (let k = 0; k < 6; k++) {
      const [a, b] = [got[k], got[(k + 1) % 6]];
      assert.ok(around[best.i].some((f) => f.includes(a) && f.includes(b)), `ring edge ${a}-${b} is not a triangle`);
    }
    // The inset's star is those neighbours projected onto the tangent plane: lengths of the
    // projected spokes are at most, and within 5 % of, the 3D edge lengths.
    const ring = JSON.parse(await inset.getAttribute('data-ring'));
    assert.equal(await inset.getAttribute('data-star'), 'mesh');
    const p0 = mesh.v[best.i];
    ring.forEach(([x, y], k) => {
      const e = Math.hypot(...mesh.v[got[k]].map((c, d) => c - p0[d]));
      const r = Math.hypot(x, y);
      assert.ok(r <= e * (1 + 1e-9) && r >= 0.95 * e, `spoke ${k}: projected ${r}, 3D ${e}`);
    });
    assert.match(await byId(page, 'teach-verdict').getAttribute('data-verdict'), /^(valid|invalid)$/);
    assert.equal(await byId(page, 'pick-marker').isVisible(), true, 'the picked vertex is marked');
    await inset.screenshot({ path: `${SHOTS}/teach-picked-vertex.png` });
    // Dragging a star vertex still changes the inset's star (only that vertex moves).
    const [hx, hy] = await handle(page, 2);
    const [cx, cy] = await handle(page, -1);
    await page.mouse.move(hx, hy);
    await page.mouse.down();
    for (let k = 1; k <= 6; k++) await page.mouse.move(hx + ((cx - hx) * 0.3 * k) / 6, hy + ((cy - hy) * 0.3 * k) / 6);
    await page.mouse.up();
    const ring2 = JSON.parse(await inset.getAttribute('data-ring'));
    ring2.forEach((q, k) => assert.equal(q[0] === ring[k][0] && q[1] === ring[k][1], k !== 2, `vertex ${k} after dragging vertex 2`));
    // Orbiting the 3D view by a drag still works and does not pick.
    const cam0 = await page.evaluate(() => Array.from(window.dupin.viewer.camera()));
    await drag(page, 60, 0);
    const cam1 = await page.evaluate(() => Array.from(window.dupin.viewer.camera()));
    assert.notDeepEqual(cam1, cam0, 'the drag orbits');
    assert.equal(await picked(page), String(best.i), 'a drag is not a click');
    await drag(page, -60, 0);
    // The hexagon mesh: the same screen point picks the same triangulation vertex.
    await page.evaluate((c) => window.dupin.viewer.setCamera(c), cam0);
    await byId(page, 'step').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase !== 'hexagons');
    await page.evaluate(() => { document.querySelector('[data-testid=teach-inset]').dataset.pickedVertex = ''; });
    await page.mouse.click(best.q.x, best.q.y);
    await page.waitForFunction((i) => document.querySelector('[data-testid=teach-inset]').dataset.pickedVertex === String(i), best.i);
    assert.deepEqual(errors, [], 'console errors');
  } finally {
    await browser.close();
  }
});

test('teach inset for a class: the construction stays in view, steps back, keys move the star, labels, enlarge, export, Escape', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'teach').click();
    const inset = byId(page, 'teach-inset');
    await page.waitForFunction(() => document.querySelector('[data-testid=teach-inset]').dataset.star);
    // Every element is labelled.
    const labels = await inset.locator('text.teach-label').allTextContents();
    for (const l of ['Dupin indicatrix', 'Dupin hexagon', 'Dupin center']) assert.ok(labels.includes(l), `${l} in ${labels}`);
    // The section 5.1 construction, to its last step: every point inside the view.
    let n = 0;
    while (true) {
      await byId(page, 'teach-step').click();
      const caption = await byId(page, 'teach-caption').textContent();
      const m = caption.match(/^Step (\d+)\/(\d+)/);
      if (!m) break;
      n = Number(m[1]);
      const outside = await page.evaluate(() => {
        const svg = document.querySelector('[data-testid=teach-inset]');
        const box = svg.getBoundingClientRect();
        return [...svg.querySelectorAll('circle')].filter((c) => {
          const r = c.getBoundingClientRect();
          const [x, y] = [r.left + r.width / 2, r.top + r.height / 2];
          return x < box.left - 0.5 || x > box.right + 0.5 || y < box.top - 0.5 || y > box.bottom + 0.5;
        }).length;
      });
      assert.equal(outside, 0, `step ${n}: ${outside} points outside the inset`);
      if (n === Number(m[2])) break;
    }
    assert.ok(n >= 2, `${n} construction steps`);
    await byId(page, 'teach-step-back').click();
    assert.match(await byId(page, 'teach-caption').textContent(), new RegExp(`^Step ${n - 1}/`));
    // Keyboard: a focused star vertex moves with the arrow keys.
    const before = await inset.getAttribute('data-ring');
    await inset.locator('[data-vertex="2"]').focus();
    await page.keyboard.press('ArrowRight');
    await page.keyboard.press('ArrowUp');
    assert.notEqual(await inset.getAttribute('data-ring'), before);
    assert.equal(await page.evaluate(() => document.activeElement?.dataset.vertex), '2');
    // Enlarge for a class, and back.
    await byId(page, 'teach-enlarge').click();
    const big = await inset.boundingBox();
    assert.ok(big.width > 320, `enlarged inset ${big.width} px`);
    await byId(page, 'teach-enlarge').click();
    // Exports for slides.
    const [svgDl] = await Promise.all([page.waitForEvent('download'), byId(page, 'teach-svg').click()]);
    const text = (await import('node:fs')).readFileSync(await svgDl.path(), 'utf8');
    assert.match(text, /^<svg[^>]*xmlns="http:\/\/www.w3.org\/2000\/svg"/);
    assert.match(text, /Dupin indicatrix/);
    const [pngDl] = await Promise.all([page.waitForEvent('download'), byId(page, 'teach-png').click()]);
    const png = (await import('node:fs')).readFileSync(await pngDl.path());
    assert.equal(png.toString('latin1', 1, 4), 'PNG');
    // Escape closes the inset.
    await page.keyboard.press('Escape');
    assert.equal(await byId(page, 'teach-panel').isHidden(), true);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
