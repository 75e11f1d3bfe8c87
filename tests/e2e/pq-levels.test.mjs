// PQ scenes stepped level by level (issue 7, "PQ, conical and circular scenes with the
// subdivision hierarchy stepped level by level, offsets and support beams toggled"):
// `conical-station` one step at a time shows the control mesh and at least two subdivision
// levels, every step changes the metrics and the picture, and the run ends PQ and conical to
// 1e-10; the offset and support toggles change the picture and their beams are planar; a bad
// face distance gets an inline message; the copied URL restores the toggles; non-conical
// scenes disable the toggles with a reason. Screenshots: target/e2e/pq-levels-*.png.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, exportText, metrics, openPage, pixelStats, shot, waitSteps } from './harness.mjs';

const KEYS = ['phase', 'level', 'iteration', 'faces', 'maxPlanarity', 'conicalResidual'];

/** Waits until the layer info shows `beams` (a number) or is empty (`null`). */
async function waitLayers(page, on) {
  await page.waitForFunction((want) => {
    const d = document.querySelector('[data-testid=layer-info]').dataset;
    return want ? d.beams !== undefined : d.beams === undefined;
  }, on, { timeout: 60_000 });
}

test('conical-station steps level by level; offset and support beams toggle and restore', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await byId(page, 'scene-select').selectOption('conical-station');
    await page.waitForFunction(() => new URLSearchParams(location.hash.slice(1)).get('scene') === 'conical-station', null, { timeout: 120_000 });
    await waitSteps(page, 1);
    let prev = await metrics(page);
    assert.equal(prev.phase, 'control', 'the first step shows the control mesh');
    assert.equal(prev.level, '0');
    let prevShot = await shot(page, 'pq-levels-step1');
    const levels = new Set([prev.level]);
    const phases = new Set([prev.phase]);
    for (let n = 2; prev.phase !== 'done'; n++) {
      assert.ok(n < 200, 'the run never finishes');
      await byId(page, 'step').click();
      await waitSteps(page, n);
      const cur = await metrics(page);
      assert.ok(KEYS.some((k) => cur[k] !== prev[k]), `step ${n} left the metrics unchanged`);
      const curShot = await shot(page, `pq-levels-step${n}`);
      const st = await pixelStats(page, curShot, prevShot);
      assert.ok(st.covered > 0.01, `step ${n} looks like the background`);
      assert.ok(st.differing > 0, `step ${n} (${cur.phase}, level ${cur.level}) looks exactly like step ${n - 1}`);
      levels.add(cur.level);
      phases.add(cur.phase);
      [prev, prevShot] = [cur, curShot];
    }
    assert.ok(levels.has('1') && levels.has('2'), `subdivision levels seen: ${[...levels]}`);
    for (const p of ['control', 'subdivide', 'perturb', 'done']) assert.ok(phases.has(p), `no ${p} step`);
    assert.ok(Number(prev.maxPlanarity) <= 1e-10, `max planarity ${prev.maxPlanarity}`);
    assert.ok(Number(prev.conicalResidual) <= 1e-10, `conical residual ${prev.conicalResidual}`);
    const panel = await page.locator('[data-metric="conical-residual"]').textContent();
    assert.match(panel, /rad/, 'the panel shows the conical residual');
    assert.match(await page.locator('[data-metric="level"]').textContent(), /^2 of 2$/);

    // Offset, then support beams: each changes the picture; the beams are planar.
    assert.equal(await byId(page, 'toggle-offset').isDisabled(), false);
    await byId(page, 'toggle-offset').check();
    await waitLayers(page, true);
    const offsetShot = await shot(page, 'pq-levels-offset');
    assert.ok((await pixelStats(page, offsetShot, prevShot)).differing > 0.001, 'the offset toggle did not change the picture');
    await byId(page, 'toggle-support').check();
    await page.waitForFunction(() => new URLSearchParams(location.hash.slice(1)).get('support') === '1');
    // The worker answers the toggle with a new state; wait for a frame of it.
    await page.waitForTimeout(300);
    const supportShot = await shot(page, 'pq-levels-support');
    assert.ok((await pixelStats(page, supportShot, offsetShot)).differing > 0.001, 'the support toggle did not change the picture');
    const info = await byId(page, 'layer-info').evaluate((e) => ({ ...e.dataset }));
    assert.ok(Number(info.beams) > 0 && Number(info.beamPlanarity) <= 1e-9, `beams ${JSON.stringify(info)}`);

    // A bad face distance: inline message, the layers stay as they were, the page goes on.
    await byId(page, 'offset-distance').fill('0');
    await byId(page, 'offset-distance').dispatchEvent('change');
    assert.match(await byId(page, 'offset-distance-error').textContent(), /distance/);
    await byId(page, 'offset-distance').fill('0.3');
    await byId(page, 'offset-distance').dispatchEvent('change');
    assert.equal(await byId(page, 'offset-distance-error').textContent(), '');
    await page.waitForFunction(() => new URLSearchParams(location.hash.slice(1)).get('dist') === '0.3');
    await page.waitForFunction(() => document.querySelector('[data-testid=layer-info]').textContent.includes('beams'));

    // The CSV schedule of the conical mesh carries its node axes and planar beams.
    const tables = (await exportText(page, 'export-csv')).split('\n\n');
    assert.equal(tables.length, 3, 'panels, nodes and beams');
    assert.match(tables[1], /^node,x_m,y_m,z_m,axis_x,axis_y,axis_z,offset_mm\n/);
    const beams = tables[2].trim().split('\n');
    assert.equal(beams[0], 'beam,node_a,node_b,length_mm,max_planarity_mm');
    assert.equal(beams.length - 1, Number(info.beams), 'one row per beam');
    assert.ok(beams.slice(1).every((r) => Number(r.split(',')[4]) <= 0.001), 'beams planar to 0.001 mm');

    // The copied URL restores scene, steps and both toggles.
    const hash = await page.evaluate(() => location.hash);
    const done = await metrics(page);
    await new Promise((r) => setTimeout(r, 500));
    const { browser: b2, page: p2, errors: e2 } = await openPage({ hash });
    try {
      await p2.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done', null, { timeout: 120_000 });
      await waitLayers(p2, true);
      assert.equal(await byId(p2, 'toggle-offset').isChecked(), true);
      assert.equal(await byId(p2, 'toggle-support').isChecked(), true);
      assert.equal(await byId(p2, 'offset-distance').inputValue(), '0.3');
      const again = await metrics(p2);
      for (const k of ['faces', 'level', 'iteration', 'maxPlanarity', 'conicalResidual']) assert.equal(again[k], done[k], `restored ${k}`);
      const restoredShot = await shot(p2, 'pq-levels-restored');
      assert.ok((await pixelStats(p2, restoredShot)).covered > 0.03);
      assert.deepEqual(e2, [], 'console errors (restored page)');
    } finally {
      await b2.close();
    }

    // Toggling off removes the layers again.
    await byId(page, 'toggle-offset').uncheck();
    await byId(page, 'toggle-support').uncheck();
    await waitLayers(page, false);

    // A non-conical scene: toggles disabled with a reason.
    await byId(page, 'scene-select').selectOption('developable-strips');
    await page.waitForFunction(() => document.querySelector('[data-testid=toggle-offset]').disabled, null, { timeout: 60_000 });
    assert.match(await byId(page, 'offset-reason').textContent(), /conical/);
    assert.deepEqual(errors, [], 'console errors');
  } finally {
    await browser.close();
  }
});
