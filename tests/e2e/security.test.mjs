// What the page lets in: `cargo xtask serve` sends a Content-Security-Policy that the whole page
// works under (a violation is a console error, and every e2e test fails on console errors); the
// page requests nothing outside its origin (checked in every test by the harness); text from the
// URL is never markup.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { URL_BASE, byId, openPage, waitDone, waitSteps } from './harness.mjs';

test('the page runs under its Content-Security-Policy and takes no markup from the URL', async () => {
  const { browser, page, errors } = await openPage({ hash: '#scene=pq-catmull-clark' });
  try {
    const doc = await page.request.get(URL_BASE);
    const csp = doc.headers()['content-security-policy'] ?? '';
    for (const rule of ["default-src 'self'", "script-src 'self' 'wasm-unsafe-eval'", "object-src 'none'", "frame-ancestors 'none'"]) {
      assert.ok(csp.includes(rule), `CSP lacks ${rule}: ${csp}`);
    }
    for (const file of ['main.js', 'worker.js', 'pkg/dupin_web_bg.wasm']) {
      const r = await page.request.get(URL_BASE + file);
      assert.ok(r.headers()['content-security-policy'], `${file} is served without a CSP`);
    }
    await waitSteps(page, 1);
    await byId(page, 'play').click();
    await waitDone(page);
    // Markup in every field the URL sets goes nowhere near the DOM as markup.
    const payload = encodeURIComponent('<img src=x onerror="window.__injected=1">');
    for (const key of ['scene', 'surface', 'method', 'init', 'color', 'backend', 'p.R', 'size', 'cam']) {
      await page.evaluate((h) => { location.hash = h; }, `#scene=free&${key}=${payload}`);
      await page.waitForTimeout(100);
    }
    await page.evaluate((h) => { location.hash = h; }, `#scene=${payload}`);
    await page.waitForTimeout(300);
    assert.equal(await page.evaluate(() => document.querySelectorAll('img[src="x"]').length + (window.__injected ?? 0)), 0);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
