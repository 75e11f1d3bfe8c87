// The 2D hexagonal Delaunay tab: points added by clicks, stepped to completion, angles within the
// simple refinement's bounds [30, 120] degrees (Sußner & Greiner, section 4); refusals inline.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, openPage, pixelStats } from './harness.mjs';

test('2D tab: click points, step to completion, angles within [30, 120]', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'hexd').click();
    const canvas = byId(page, 'hexd-canvas');
    await canvas.waitFor();
    const box = await canvas.boundingBox();
    // A fixed scatter around the centre (deterministic).
    const pts = [[0.5, 0.5], [0.58, 0.43], [0.41, 0.62], [0.66, 0.6], [0.45, 0.38], [0.52, 0.55], [0.37, 0.47]];
    for (const [fx, fy] of pts) await page.mouse.click(box.x + fx * box.width, box.y + fy * box.height);
    const status = byId(page, 'hexd-status');
    assert.match(await status.textContent(), /7 points/);
    assert.equal(await status.getAttribute('data-done'), 'false');
    const hist = byId(page, 'hexd-histogram');
    const h0 = await hist.screenshot();
    let steps = 0;
    while (!(await byId(page, 'hexd-step').isDisabled())) {
      await byId(page, 'hexd-step').click();
      steps++;
      assert.ok(steps < 500, 'refinement never finishes');
    }
    assert.ok(steps >= 2, `only ${steps} steps`);
    assert.equal(await status.getAttribute('data-done'), 'true');
    // The last click may only discover that nothing is left to split.
    const taken = Number(await status.getAttribute('data-steps'));
    assert.ok(taken >= steps - 1 && taken <= steps, `${taken} steps after ${steps} clicks`);
    const min = Number(await status.getAttribute('data-min-angle'));
    const max = Number(await status.getAttribute('data-max-angle'));
    assert.ok(min >= 30 - 1e-6 && max <= 120 + 1e-6, `angles ${min}..${max}`);
    assert.ok(Number(await status.getAttribute('data-triangles')) > 7);
    const shot = await canvas.screenshot({ path: `${SHOTS}/hexd-simple.png` });
    assert.ok((await pixelStats(page, shot)).covered > 0.05);
    const h1 = await hist.screenshot({ path: `${SHOTS}/hexd-histogram.png` });
    assert.ok((await pixelStats(page, h1, h0)).differing > 0.005, 'the histogram fills in');
    // Dragging a point restarts the refinement from the bounding hexagon.
    const [fx, fy] = pts[0];
    await page.mouse.move(box.x + fx * box.width, box.y + fy * box.height);
    await page.mouse.down();
    await page.mouse.move(box.x + fx * box.width + 20, box.y + fy * box.height + 10, { steps: 4 });
    await page.mouse.up();
    assert.equal(await status.getAttribute('data-steps'), '0');
    assert.match(await status.textContent(), /7 points/);
    assert.deepEqual(errors, [], 'console errors');
  } finally {
    await browser.close();
  }
});

test('2D tab: no click is lost, nothing is drawn before a step, the picture stays on the canvas', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'hexd').click();
    const canvas = byId(page, 'hexd-canvas');
    const box = await canvas.boundingBox();
    const status = byId(page, 'hexd-status');
    const count = async () => Number((await status.textContent()).split(' ')[0]);
    // Bright pixels of the dual triangulation's lines (#e6e8ee), all over and on the border.
    const bright = () => page.evaluate(() => {
      const c = document.querySelector('[data-testid=hexd-canvas]');
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let all = 0, border = 0;
      for (let y = 0; y < c.height; y++) for (let x = 0; x < c.width; x++) {
        const k = 4 * (y * c.width + x);
        if (d[k] > 150 && d[k + 1] > 150 && d[k + 2] > 150) {
          all++;
          if (x < 2 || y < 2 || x >= c.width - 2 || y >= c.height - 2) border++;
        }
      }
      return { all, border };
    });
    // Points near the corners of the canvas: their bounding hexagon reaches far outside it.
    const spots = [[0.04, 0.05], [0.95, 0.06], [0.5, 0.5], [0.06, 0.94], [0.93, 0.95], [0.3, 0.7]];
    for (const [fx, fy] of spots) await page.mouse.click(box.x + fx * box.width, box.y + fy * box.height);
    assert.equal(await count(), spots.length);
    assert.match(await status.textContent(), /press Step or Run/);
    assert.equal((await bright()).all, 0, 'no triangulation drawn before the first step');
    // A click 8 px beside a point (inside the 10 px grab radius, off its dot) adds a point...
    await page.mouse.click(box.x + 0.5 * box.width + 8, box.y + 0.5 * box.height);
    assert.equal(await count(), spots.length + 1);
    // ...and one on a dot says why nothing was added.
    await page.mouse.click(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
    assert.equal(await count(), spots.length + 1);
    assert.match(await status.textContent(), /already there: drag it/);
    await byId(page, 'hexd-run').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=hexd-status]').dataset.done === 'true', null, { timeout: 60_000 });
    const lit = await bright();
    assert.ok(lit.all > 1000, `${lit.all} triangulation pixels after the run`);
    assert.equal(lit.border, 0, 'the triangulation reaches the canvas border');
    await canvas.screenshot({ path: `${SHOTS}/hexd-corners.png` });
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('2D tab: segments are accepted and the extended mode surfaces any core message inline', async () => {
  const { browser, page } = await openPage();
  try {
    await byId(page, 'hexd').click();
    const box = await byId(page, 'hexd-canvas').boundingBox();
    const status = byId(page, 'hexd-status');
    await page.mouse.click(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
    await page.mouse.click(box.x + 0.6 * box.width, box.y + 0.45 * box.height);
    await byId(page, 'hexd-mode').selectOption('extended');
    const ext = await status.textContent();
    if (await status.evaluate((e) => e.classList.contains('error'))) assert.match(ext, /not implemented/);
    await byId(page, 'hexd-mode').selectOption('simple');
    assert.ok(!(await status.evaluate((e) => e.classList.contains('error'))));
    await byId(page, 'hexd-tool').selectOption('segments');
    await page.mouse.click(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
    await page.mouse.click(box.x + 0.6 * box.width, box.y + 0.45 * box.height);
    // PSLG input (section 7): a segment between the two points is accepted and can be stepped.
    const text = await status.textContent();
    assert.ok(!(await status.evaluate((e) => e.classList.contains('error'))), text);
    assert.ok(!(await byId(page, 'hexd-step').isDisabled()));
    await byId(page, 'hexd-clear').click();
    assert.ok(!(await status.evaluate((e) => e.classList.contains('error'))));
  } finally {
    await browser.close();
  }
});

test('2D tab: a point set runs to the end at once, and the picture leaves as SVG and PNG', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'hexd').click();
    const status = byId(page, 'hexd-status');
    await byId(page, 'hexd-tool').selectOption('segments');
    assert.match(await status.textContent(), /segments: click a point .* then the other end/);
    await byId(page, 'hexd-tool').selectOption('points');
    for (const set of ['line', 'clustered', 'random']) {
      await byId(page, 'hexd-points').selectOption(set);
      assert.equal(await status.getAttribute('data-steps'), '0');
      const t0 = Date.now();
      await byId(page, 'hexd-run').click();
      await page.waitForFunction(() => document.querySelector('[data-testid=hexd-status]').dataset.done === 'true', null, { timeout: 30_000 });
      assert.ok(Date.now() - t0 < 15_000, `${set}: ${Date.now() - t0} ms`);
      assert.ok(Number(await status.getAttribute('data-steps')) >= 2, set);
      assert.ok(Number(await status.getAttribute('data-min-angle')) >= 30 - 1e-9, set);
      assert.ok(Number(await status.getAttribute('data-max-angle')) <= 120 + 1e-9, set);
    }
    const triangles = Number(await status.getAttribute('data-triangles'));
    const [svgDl] = await Promise.all([page.waitForEvent('download'), byId(page, 'hexd-svg').click()]);
    const svg = (await import('node:fs')).readFileSync(await svgDl.path(), 'utf8');
    const parsed = await page.evaluate((text) => {
      const doc = new DOMParser().parseFromString(text, 'image/svg+xml');
      return { error: doc.querySelector('parsererror')?.textContent ?? null, open: doc.querySelectorAll('polygon[fill=none]').length, points: doc.querySelectorAll('circle').length };
    }, svg);
    assert.equal(parsed.error, null);
    assert.equal(parsed.open, triangles);
    assert.equal(parsed.points, 30);
    const [pngDl] = await Promise.all([page.waitForEvent('download'), byId(page, 'hexd-png').click()]);
    const png = (await import('node:fs')).readFileSync(await pngDl.path());
    assert.equal(png.toString('latin1', 1, 4), 'PNG');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('2D tab: Run at once on 30 and 300 random points (the times BENCHMARKS.md quotes)', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'hexd').click();
    const status = byId(page, 'hexd-status');
    for (const [set, n] of [['random', 30], ['dense', 300]]) {
      await byId(page, 'hexd-points').selectOption(set);
      assert.match(await status.textContent(), new RegExp(`^${n} points`));
      const ms = await page.evaluate(() => new Promise((resolve) => {
        const s = document.querySelector('[data-testid=hexd-status]');
        const t0 = performance.now();
        new MutationObserver((_, o) => { if (s.dataset.done === 'true') { o.disconnect(); resolve(performance.now() - t0); } })
          .observe(s, { attributes: true, attributeFilter: ['data-done'] });
        document.querySelector('[data-testid=hexd-run]').click();
      }));
      const steps = Number(await status.getAttribute('data-steps'));
      const triangles = Number(await status.getAttribute('data-triangles'));
      console.log(`# 2D Run at once, ${n} points: ${ms.toFixed(0)} ms, ${steps} steps, ${triangles} triangles`);
      assert.ok(ms < 10_000, `${n} points took ${ms} ms`);
      assert.ok(Number(await status.getAttribute('data-min-angle')) >= 30 - 1e-9);
      assert.ok(Number(await status.getAttribute('data-max-angle')) <= 120 + 1e-9);
    }
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('2D tab on a phone: the picture fits the screen and a tap adds a point where it lands', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await page.setViewportSize({ width: 390, height: 844 });
    await byId(page, 'hexd').click();
    const canvas = byId(page, 'hexd-canvas');
    await canvas.scrollIntoViewIfNeeded();
    const box = await canvas.boundingBox();
    assert.ok(box.x >= 0 && box.x + box.width <= 390.5, `canvas spans ${box.x}..${box.x + box.width}`);
    await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
    await page.waitForFunction(() => /^1 points/.test(document.querySelector('[data-testid=hexd-status]').textContent));
    assert.ok(await byId(page, 'hexd-run').isVisible());
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
