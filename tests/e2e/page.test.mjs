// The page in headless Chromium: both backends draw, orbit, keep the contract's test ids, restore
// from the URL, export OBJ and reject bad input inline.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, drag, metrics, openPage, pixelStats, shot, waitSteps } from './harness.mjs';

for (const [backend, webgpu] of [['WebGPU', true], ['WebGL2', false]]) {
  test(`${backend}: loads cleanly, draws the torus and orbits on drag`, async () => {
    const { browser, page, errors } = await openPage({ webgpu });
    try {
      assert.equal((await byId(page, 'status').textContent()).trim(), backend);
      const first = await shot(page, `${backend.toLowerCase()}-initial`);
      const { covered } = await pixelStats(page, first);
      assert.ok(covered > 0.05, `only ${(covered * 100).toFixed(1)}% of the canvas differs from the background`);
      await drag(page, 160, 40);
      const second = await shot(page, `${backend.toLowerCase()}-dragged`);
      const { differing } = await pixelStats(page, first, second);
      assert.ok(differing > 0.01, `a drag changed only ${(differing * 100).toFixed(2)}% of pixels`);
      // The browser's own screenshot of the canvas element shows the same picture.
      const composited = await byId(page, 'canvas').screenshot({ path: `${SHOTS}/${backend.toLowerCase()}-page.png` });
      const seen = await pixelStats(page, composited);
      assert.ok(seen.covered > 0.05, `page screenshot: only ${(seen.covered * 100).toFixed(1)}% covered`);
      assert.deepEqual(errors, [], 'console errors');
    } finally {
      await browser.close();
    }
  });
}

test('contract test ids and metrics are present; a first visit opens on a finished result', async () => {
  const { browser, page } = await openPage();
  try {
    for (const id of ['canvas', 'scene-select', 'step', 'play', 'reset', 'export-obj', 'status', 'metrics']) {
      assert.equal(await byId(page, id).count(), 1, `data-testid=${id}`);
    }
    // No hash: the P-Hex paper's Fig. 1 roof, run to the end, and one line on what to press.
    const m = byId(page, 'metrics');
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done');
    assert.equal(await byId(page, 'scene-select').inputValue(), 'cyclide-architecture');
    assert.equal(await m.getAttribute('data-iteration'), '0');
    assert.equal(Number(await m.getAttribute('data-faces')), 3200);
    assert.equal(Number(await m.getAttribute('data-invalid-faces')), 0);
    assert.ok(Number(await m.getAttribute('data-max-planarity')) < 1e-12);
    assert.ok(await byId(page, 'step').isDisabled());
    assert.match(await byId(page, 'scene-description').textContent(), /planar panels .* drag to orbit .* Play .* open your own design/);
    assert.ok(await byId(page, 'progress').isHidden());
    // The design's dimensions in metres at the page's panel edge, and the legend's units.
    const dims = async () => (await page.locator('[data-metric=dimensions]').textContent()).split(' m')[0].split(' × ').map(Number);
    const at15 = await dims();
    assert.equal(at15.length, 3);
    assert.ok(at15.every((x) => x > 1 && x < 1000), `dimensions ${at15}`);
    assert.match(await byId(page, 'legend-caption').textContent(), /÷ mean edge: at a 1.5 m edge, 1e-6 is 0.0015 mm/);
    await byId(page, 'panel-edge').fill('3');
    await byId(page, 'panel-edge').dispatchEvent('change');
    const at3 = await dims();
    at3.forEach((x, k) => assert.ok(Math.abs(x / at15[k] - 2) < 0.05, `${x} vs ${at15[k]} at twice the edge`));
    assert.match(await byId(page, 'legend-caption').textContent(), /at a 3 m edge, 1e-6 is 0.003 mm/);
    // Picking a scene ends the welcome: its own description, ready to play.
    await byId(page, 'scene-select').selectOption('sphere-radial');
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase !== 'done');
    assert.doesNotMatch(await byId(page, 'scene-description').textContent(), /drag to orbit/);
  } finally {
    await browser.close();
  }
});

test('a copied URL restores the configuration', async () => {
  const { browser, page } = await openPage({ hash: '#scene=torus&R=3&r=1.25' });
  try {
    assert.equal(await byId(page, 'param-R').inputValue(), '3');
    assert.equal(await byId(page, 'param-r').inputValue(), '1.25');
    const url = page.url();
    assert.match(url, /R=3/);
    const faces = await byId(page, 'metrics').getAttribute('data-faces');
    const again = await page.context().newPage();
    await again.goto(url);
    await again.waitForFunction(() => document.body.dataset.ready === 'true');
    assert.equal(await byId(again, 'param-r').inputValue(), '1.25');
    assert.equal(await byId(again, 'metrics').getAttribute('data-faces'), faces);
  } finally {
    await browser.close();
  }
});

test('the exported OBJ parses and has the reported face count', async () => {
  const { browser, page } = await openPage();
  try {
    const [download] = await Promise.all([page.waitForEvent('download'), byId(page, 'export-obj').click()]);
    const path = await download.path();
    const text = (await import('node:fs')).readFileSync(path, 'utf8');
    const lines = text.split('\n').filter(Boolean);
    const v = lines.filter((l) => l.startsWith('v ')), f = lines.filter((l) => l.startsWith('f '));
    assert.equal(v.length + f.length, lines.length, 'only v and f statements');
    for (const l of v) assert.equal(l.split(' ').slice(1).map(Number).filter(Number.isFinite).length, 3);
    for (const l of f) {
      const idx = l.split(' ').slice(1).map(Number);
      assert.ok(idx.every((i) => Number.isInteger(i) && i >= 1 && i <= v.length));
    }
    assert.equal(String(f.length), await byId(page, 'metrics').getAttribute('data-faces'));
  } finally {
    await browser.close();
  }
});

test('bad input shows an inline message and leaves the page usable', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=torus' });
  try {
    const faces = await byId(page, 'metrics').getAttribute('data-faces');
    await byId(page, 'param-R').fill('-5');
    await byId(page, 'param-R').dispatchEvent('change');
    assert.match(await byId(page, 'param-R-error').textContent(), /R must be a positive number/);
    assert.equal(await byId(page, 'metrics').getAttribute('data-faces'), faces);
    await byId(page, 'param-R').fill('4');
    await byId(page, 'param-R').dispatchEvent('change');
    assert.equal(await byId(page, 'param-R-error').textContent(), '');
    assert.match(page.url(), /R=4/);
    assert.equal((await byId(page, 'status').textContent()).trim(), 'WebGPU');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('phone and tablet: every button is on screen, none overlaps another, the view is not cropped away', async () => {
  for (const [w, h] of [[390, 844], [820, 1180]]) {
    const { browser, page, errors } = await openPage();
    try {
      await page.setViewportSize({ width: w, height: h });
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      const boxes = await page.$$eval('header button, header select, header .open-design', (els) => els.map((e) => {
        const r = e.getBoundingClientRect();
        return { id: e.dataset.testid ?? e.textContent.trim(), x: r.left, y: r.top, r: r.right, b: r.bottom };
      }));
      assert.ok(boxes.length >= 12, `${boxes.length} controls`);
      for (const a of boxes) {
        assert.ok(a.x >= 0 && a.r <= w + 0.5, `${w}px: ${a.id} is off screen (${a.x}..${a.r})`);
        for (const b of boxes) {
          if (a === b) continue;
          const overlap = Math.min(a.r, b.r) - Math.max(a.x, b.x) > 1 && Math.min(a.b, b.b) - Math.max(a.y, b.y) > 1;
          assert.ok(!overlap, `${w}px: ${a.id} overlaps ${b.id}`);
        }
      }
      const canvas = await byId(page, 'canvas').boundingBox();
      assert.ok(canvas.width >= 0.9 * w && canvas.height >= 0.3 * h, `${w}px: the view is ${canvas.width} x ${canvas.height}`);
      // The colour mode and legend are reachable by scrolling the page, not hidden in a box.
      await byId(page, 'color-mode').scrollIntoViewIfNeeded();
      assert.ok(await byId(page, 'color-mode').isVisible());
      assert.deepEqual(errors, []);
    } finally {
      await browser.close();
    }
  }
});

test('every scene says in one sentence what it shows, with its paper figure', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=torus' });
  try {
    assert.match(await byId(page, 'scene-description').textContent(), /flat panels.*press Play/);
    // The torus preview reads as a preview, not as a finished run with zero planarity.
    assert.match(await byId(page, 'metrics').textContent(), /smooth surface preview, no panels yet/);
    assert.doesNotMatch(await byId(page, 'metrics').textContent(), /max planarity/);
    const scenes = await byId(page, 'scene-select').evaluate((s) => [...s.options].map((o) => o.value));
    for (const scene of scenes.filter((s) => !['torus', 'free'].includes(s))) {
      await byId(page, 'scene-select').selectOption(scene);
      await page.waitForFunction((s) => location.hash.includes(`scene=${s}`), scene, { timeout: 60_000 });
      assert.match(await byId(page, 'scene-description').textContent(), /\((P-Hex|conical) paper, (Figs?\.|section) [0-9].*\)\. Press Play/, scene);
    }
    await byId(page, 'scene-select').selectOption('free');
    assert.match(await byId(page, 'scene-description').textContent(), /library surface/);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a run shows a progress bar: steps done under the core\'s bound on the steps left, and a time at the current pace', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=cyclide-prescribed' });
  try {
    const bar = byId(page, 'progress');
    const m = byId(page, 'metrics');
    assert.ok(await bar.isHidden(), 'no bar before the run moves');
    let lastLeft = Infinity;
    for (let k = 2; k <= 4; k++) {
      await byId(page, 'step').click();
      await page.waitForFunction((n) => document.querySelector('[data-testid=metrics]').dataset.steps === String(n), k);
      await bar.waitFor({ state: 'visible' });
      const left = Number(await bar.getAttribute('data-steps-left'));
      assert.ok(left > 0 && left < lastLeft, `steps left ${left} after ${lastLeft}`);
      lastLeft = left;
      const value = await bar.locator('progress').evaluate((p) => p.value);
      assert.ok(Math.abs(value - k / (k + left)) < 1e-9, `bar at ${value} after ${k} steps with ${left} left`);
      assert.match(await bar.textContent(), new RegExp(`step ${k} · at most ${left} more · [0-9.]+ (s|min)`));
    }
    // Played to the end: the steps taken stay under the first bound, and the bar goes away.
    await byId(page, 'play').click();
    await page.waitForFunction(() => ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 60_000 });
    assert.ok(Number(await m.getAttribute('data-steps')) <= 4 + lastLeft);
    await bar.waitFor({ state: 'hidden' });
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a triangulation revealed a layer at a time is drawn from appended layers, the same as its whole mesh', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=cyclide-prescribed' });
  // FNV-1a over the bytes of every held array, and how many states were appended to them.
  const held = () => page.evaluate(() => {
    const s = window.dupin.shownArrays;
    const digest = {};
    for (const [name, a] of Object.entries(s.arrays())) {
      let h = 0x811c9dc5;
      for (const b of new Uint8Array(a.buffer, a.byteOffset, a.byteLength)) h = Math.imul(h ^ b, 0x01000193) >>> 0;
      digest[name] = `${a.length}:${h}`;
    }
    return { digest, appended: s.appended };
  });
  try {
    for (let k = 2; k <= 6; k++) {
      await byId(page, 'step').click();
      await waitSteps(page, k);
    }
    assert.equal((await metrics(page)).phase, 'triangulation');
    const appended = await held();
    assert.ok(appended.appended >= 4, `${appended.appended} states appended`);
    const states = await page.evaluate(() => window.dupin.stepLog.length);
    await page.evaluate(() => window.dupin.resync());
    await page.waitForFunction((n) => window.dupin.stepLog.length > n, states);
    const whole = await held();
    assert.equal(whole.appended, 0);
    assert.deepEqual(appended.digest, whole.digest);
    assert.ok(Number(whole.digest.indices.split(':')[0]) > 0);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a link whose run the core refuses (over the page\'s face limit) opens ready, says why, and stays usable', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=free&surface=torus&method=prescribed&size=0.025' });
  try {
    assert.match(await byId(page, 'status').textContent(), /limit of 100000 .* use a larger size/);
    await byId(page, 'scene-select').selectOption('sphere-radial');
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    assert.doesNotMatch(await byId(page, 'status').textContent(), /limit/);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
