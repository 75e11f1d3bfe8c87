// The page survives what goes wrong: a wasm trap and an out-of-memory in the solver worker
// (forced through window.dupin.fault) each show a message, and the page goes on from its last
// state; Stop cancels a long step at once; a finished run that misses what it was asked ends in
// the `warning` phase with its reason, never `done`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, metrics, openPage, waitSteps } from './harness.mjs';

const status = (page) => byId(page, 'status').textContent();
// What the forced faults print on the console (the panic hook, the allocator).
const expected = (e) => /dupin panicked|debugFault|memory allocation|unreachable|Out of memory/i.test(e);

test('a trap and an out-of-memory in the worker leave the page working', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-spiral&steps=2' });
  try {
    await waitSteps(page, 2);
    for (const kind of ['trap', 'oom']) {
      const before = await metrics(page);
      await page.evaluate((k) => window.dupin.fault(k), kind);
      await page.waitForFunction(() => /restarted at step 2/.test(document.querySelector('[data-testid=status]').textContent), null, { timeout: 60_000 });
      // Step comes back with the restored state.
      await page.waitForFunction(() => !document.querySelector('[data-testid=step]').disabled, null, { timeout: 60_000 });
      await waitSteps(page, 2);
      const after = await metrics(page);
      assert.equal(after.faces, before.faces, `${kind}: the restored state differs`);
      assert.equal(after.maxPlanarity, before.maxPlanarity, `${kind}: the restored state differs`);
      // And the restored run goes on.
      await byId(page, 'step').click();
      await waitSteps(page, 3);
      await byId(page, 'reset').click();
      await waitSteps(page, 1);
      await byId(page, 'step').click();
      await waitSteps(page, 2);
    }
    assert.deepEqual(errors.filter((e) => !expected(e)), []);
  } finally {
    await browser.close();
  }
});

test('Stop cancels a long computation and returns to the last state', async () => {
  // A free-mode torus of 0.01 panels: minutes of work per step.
  const { browser, page, errors } = await openPage({ hash: '#scene=free&surface=torus&size=0.02&steps=1' });
  try {
    await waitSteps(page, 1, 180_000);
    const at = await metrics(page);
    await byId(page, 'play').click();
    await page.waitForTimeout(500);
    const t0 = Date.now();
    await byId(page, 'stop').click();
    await page.waitForFunction(() => /stopped; back at step/.test(document.querySelector('[data-testid=status]').textContent), null, { timeout: 10_000 });
    assert.ok(Date.now() - t0 < 5_000, `Stop took ${Date.now() - t0} ms`);
    await page.waitForFunction(() => !document.querySelector('[data-testid=step]').disabled, null, { timeout: 180_000 });
    await page.waitForFunction((n) => Number(document.querySelector('[data-testid=metrics]').dataset.steps) >= n, Number(at.steps), { timeout: 180_000 });
    assert.notEqual((await metrics(page)).phase, 'done');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('a missed result ends in warning with its reason, never done', async () => {
  // The free-mode torus at panel size 0.2 ends with self-intersecting faces.
  const { browser, page, errors } = await openPage({ hash: '#scene=free&surface=torus&size=0.2' });
  try {
    await waitSteps(page, 1, 120_000);
    await byId(page, 'play').click();
    await page.waitForFunction(() => ['done', 'warning'].includes(document.querySelector('[data-testid=metrics]').dataset.phase), null, { timeout: 180_000 });
    const m = await metrics(page);
    assert.equal(m.phase, 'warning');
    assert.match(await status(page), /NOT done: .*self-intersecting/);
    assert.equal(await byId(page, 'step').isDisabled(), true);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
