// What a first visitor sees on a phone, a portrait tablet and a desktop: the page opened on its
// finished P-Hex roof, screenshotted whole and compared with reference images under the native
// render tests' tolerance (DUPIN_BLESS=1 rewrites them; look at target/e2e/screen-*.png first).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, compareWithReference, openPage, waitDone } from './harness.mjs';

const SCREENS = [
  ['phone', { width: 390, height: 844 }],
  ['tablet', { width: 820, height: 1180 }],
  ['desktop', { width: 1280, height: 800 }],
];

for (const [name, viewport] of SCREENS) {
  test(`first sight on a ${name} (${viewport.width} x ${viewport.height}) matches its reference image`, async () => {
    const { browser, page, errors } = await openPage({ viewport });
    try {
      await waitDone(page);
      // Two frames after the last mesh, so the picture is the finished one.
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      const png = await page.screenshot({
        path: `${SHOTS}/screen-${name}.png`,
        animations: 'disabled',
        caret: 'hide',
        // The only figure that changes from run to run: the worker's step time.
        mask: [page.locator('[data-metric=step-time]')],
      });
      const { differing, mean, size } = await compareWithReference(page, png, `screen-${name}`);
      assert.ok(!size, `size ${size}`);
      assert.ok(differing < 0.005 && mean < 1.5, `${name}: ${(differing * 100).toFixed(2)}% of pixels off, mean |d| ${mean.toFixed(2)}; see target/e2e/screen-${name}.png`);
      // The welcome line is on screen without scrolling.
      const box = await byId(page, 'scene-description').boundingBox();
      assert.ok(box && box.y + box.height <= viewport.height + 0.5, `${name}: welcome line below the fold at ${box?.y}`);
      assert.deepEqual(errors, []);
    } finally {
      await browser.close();
    }
  });
}
