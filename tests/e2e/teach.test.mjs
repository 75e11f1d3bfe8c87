// The teaching inset (P-Hex paper sections 3-5.1): it opens, draws, and reacts to a drag of a star
// vertex (its pixels and its Proposition 4 verdict change); the section 5.1 steps and bad input.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SHOTS, byId, openPage, pixelStats } from './harness.mjs';

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
