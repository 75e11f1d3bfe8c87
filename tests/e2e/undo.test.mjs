// Undo and redo of settings (buttons, Ctrl+Z / Ctrl+Shift+Z): every change of a setting can be
// taken back, the run comes back at the step it was left, its mesh bit for bit.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, exportText, openPage, waitSteps } from './harness.mjs';

const param = async (page, k) => page.evaluate((key) => new URLSearchParams(location.hash.slice(1)).get(key), k);

test('undo and redo walk back and forth through settings; the run returns bit for bit', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=sphere-radial' });
  try {
    await waitSteps(page, 1);
    assert.ok(await byId(page, 'undo').isDisabled(), 'nothing to undo yet');
    for (let k = 2; k <= 3; k++) { await byId(page, 'step').click(); await waitSteps(page, k); }
    const before = await exportText(page, 'export-obj');
    await byId(page, 'color-mode').selectOption('convexity');
    await page.waitForFunction(() => location.hash.includes('color=convexity'));
    await byId(page, 'scene-select').selectOption('conical-station');
    await page.waitForFunction(() => location.hash.includes('scene=conical-station'));
    assert.ok(!(await byId(page, 'undo').isDisabled()));
    // Ctrl+Z: back to the sphere at step 3, in convexity colours, the same mesh.
    await page.locator('body').click({ position: { x: 5, y: 5 } });
    await page.keyboard.press('Control+z');
    await page.waitForFunction(() => location.hash.includes('scene=sphere-radial'));
    await waitSteps(page, 3);
    assert.equal(await param(page, 'color'), 'convexity');
    assert.equal(await byId(page, 'color-mode').inputValue(), 'convexity');
    assert.equal(await exportText(page, 'export-obj'), before, 'the undone run is the same mesh, bit for bit');
    // Once more: the colour mode goes back too.
    await page.keyboard.press('Control+z');
    await page.waitForFunction(() => !location.hash.includes('color='));
    assert.equal(await byId(page, 'color-mode').inputValue(), 'planarity');
    assert.ok(await byId(page, 'undo').isDisabled(), 'back at the start');
    // Redo by keyboard, then by button.
    await page.keyboard.press('Control+Shift+z');
    await page.waitForFunction(() => location.hash.includes('color=convexity'));
    assert.ok(!(await byId(page, 'redo').isDisabled()));
    await byId(page, 'redo').click();
    await page.waitForFunction(() => location.hash.includes('scene=conical-station'));
    assert.ok(await byId(page, 'redo').isDisabled(), 'nothing left to redo');
    // A new change after an undo drops what could be redone.
    await byId(page, 'undo').click();
    await page.waitForFunction(() => location.hash.includes('scene=sphere-radial'));
    await byId(page, 'color-mode').selectOption('regularity');
    await page.waitForFunction(() => location.hash.includes('color=regularity'));
    assert.ok(await byId(page, 'redo').isDisabled());
    assert.equal(await param(page, 'scene'), 'sphere-radial');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
