// Accessibility: axe-core (Deque's rules, through @axe-core/playwright) finds no serious or
// critical violation on the main view, the teaching inset, the 2D tab and presentation mode; the
// header's controls are reachable by Tab, in order, with a visible focus ring.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { axeSerious as serious, byId, openPage } from './harness.mjs';

test('axe finds no serious or critical violation on the main view, the inset, the 2D tab and presentation mode', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    assert.deepEqual(await serious(page, 'main view'), [], 'main view');
    await byId(page, 'teach').click();
    await page.waitForFunction(() => document.querySelector('[data-testid=teach-inset]').dataset.star);
    assert.deepEqual(await serious(page, 'teaching inset'), [], 'teaching inset');
    await page.keyboard.press('Escape');
    await byId(page, 'hexd').click();
    await byId(page, 'hexd-points').selectOption('random');
    assert.deepEqual(await serious(page, '2D tab'), [], '2D tab');
    await byId(page, 'hexd').click();
    await byId(page, 'present').click();
    await page.waitForFunction(() => document.querySelector('[data-testid="present-status"]').dataset.rendered === 'true', null, { timeout: 60_000 });
    assert.deepEqual(await serious(page, 'presentation mode'), [], 'presentation mode');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('axe finds no serious or critical violation at first sight (the finished roof and its welcome line)', async () => {
  const { browser, page, errors } = await openPage();
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done');
    assert.deepEqual(await serious(page, 'first sight'), [], 'first sight');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

test('the header is operable by keyboard: Tab reaches every control in order, with a visible focus ring', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.steps === '1', null, { timeout: 60_000 });
    const reached = [];
    for (let i = 0; i < 40; i++) {
      await page.keyboard.press('Tab');
      const f = await page.evaluate(() => {
        const e = document.activeElement;
        const style = getComputedStyle(e);
        return { id: e.dataset?.testid ?? e.id ?? e.tagName, ring: style.outlineStyle !== 'none' && parseFloat(style.outlineWidth) > 0 };
      });
      if (f.id === 'play') {
        assert.ok(f.ring, 'Play shows where the focus is');
        // Enter presses it.
        await page.keyboard.press('Enter');
        await page.waitForFunction(() => Number(document.querySelector('[data-testid=metrics]').dataset.steps) > 1, null, { timeout: 60_000 });
      }
      reached.push(f.id);
    }
    for (const id of ['scene-select', 'import-file', 'step', 'play', 'export-obj', 'export-3dm', 'teach', 'hexd', 'present']) {
      assert.ok(reached.includes(id), `${id} is not reachable by Tab (${reached.join(', ')})`);
    }
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
