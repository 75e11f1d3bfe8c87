// The page's URL-hash parser under hostile hashes (a seeded mutation fuzzer: the hash parser is
// JavaScript, out of libFuzzer's reach): 200 000 in CI, HASH_FUZZ_RUNS=1000000 for a long run. readHash never throws, always returns a
// configuration inside the schema, and writeHash/readHash is a fixed point; then a few dozen of
// the worst hashes go through the live page, which must stay usable.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { byId, metrics, openPage, waitSteps } from './harness.mjs';

const RUNS = Number(process.env.HASH_FUZZ_RUNS ?? 200_000);

test('the URL-hash parser takes any hash', async () => {
  const { browser, page, errors } = await openPage({ webgpu: false });
  try {
    const result = await page.evaluate(async (runs) => {
      const cfg = await import('./config.js');
      const { wasm } = await import('./wasm.js'); // the build the page loaded, initialised
      const ctx = {
        scenes: wasm.sceneNames(),
        catalog: wasm.surfaceCatalog(),
        torusParams: Object.fromEntries(wasm.pageSchema().torus.map((p) => [p.key, { label: p.key, value: p.default }])),
      };
      const schema = cfg.schema();
      let seed = 0x9e3779b9;
      const rand = (n) => {
        seed ^= seed << 13; seed >>>= 0; seed ^= seed >>> 17; seed ^= seed << 5; seed >>>= 0;
        return seed % n;
      };
      const pick = (xs) => xs[rand(xs.length)];
      const keys = ['scene', 'surface', 'method', 'init', 'size', 'bound', 'lambda', 'mu', 'steps', 'color',
        'edge', 'offset', 'support', 'dist', 'cam', 'backend', 'R', 'r', 'p.R', 'p.r', 'p.a', 'p.c', 'x', 'edits', 'cp', ''];
      const values = ['', '0', '-0', '1', '-1', '0.5', '1e-300', '1e300', '1e400', 'NaN', 'Infinity', '-Infinity',
        '100000', '100001', '1.5', '0x10', ' 2 ', '%', '%zz', '%00', '\u0000', '\u202e', '<img src=x>', '"\'',
        'free', 'torus', 'webgl2', '1,2,3,4,5,6', '1,2,3,4,5', 'a,b,c,d,e,f', '🙂', '=', '&', '#', '+',
        '12:0.5,1,-0.25', '40+41+47:1,2,3', '40%2B41:1,2,3;7:0,0,1e300', '4+:1,2,3', '1++2:1,2,3',
        '2147483648+1:1,1,1', '1+2147483648:1,1,1', '3 4:1,2,3;', '5:1,2', 'imported', 'imported',
        '4:2,2,2.5;0:0,0,-0.5', '4:1,1,1;4:2,2,2', '-1:0,0,0', '3:1,2,3/4,5,6', '3+4:1,2,3/4,5', '3:/1,2,3', '3:1,2,3//',
        ...ctx.scenes, ...ctx.catalog.map((s) => s.name), ...schema.colorModes,
        ...schema.methods.map((m) => m.name), ...schema.initialisations.map((m) => m.name)];
      const same = (a, b) => JSON.stringify(a, (k, v) => (typeof v === 'number' ? String(v) : v))
        === JSON.stringify(b, (k, v) => (typeof v === 'number' ? String(v) : v));
      const hostile = [];
      for (let i = 0; i < runs; i++) {
        let hash = rand(4) === 0 ? '' : '#';
        const n = rand(8);
        for (let j = 0; j < n; j++) {
          if (j) hash += pick(['&', '&', '&', ';', '&&', '=']);
          hash += rand(8) === 0 ? encodeURIComponent(pick(keys)) : pick(keys);
          if (rand(6)) hash += '=' + (rand(3) === 0 ? encodeURIComponent(pick(values)) : pick(values));
        }
        let c;
        try {
          c = cfg.readHash(hash, ctx);
        } catch (e) {
          return { failed: `readHash threw ${e} for ${JSON.stringify(hash)}` };
        }
        const bad = [
          !(['torus', 'free', 'imported'].includes(c.scene) || ctx.scenes.includes(c.scene)) && 'scene',
          !(Number.isInteger(c.steps) && c.steps >= 1 && c.steps <= 100000) && 'steps',
          !schema.colorModes.includes(c.color) && 'color',
          !(Number.isFinite(c.panelEdge) && c.panelEdge > 0) && 'edge',
          !(Number.isFinite(c.layers.distance) && c.layers.distance !== 0) && 'dist',
          !(c.camera === null || (c.camera.length === 6 && c.camera.every(Number.isFinite))) && 'cam',
          !['auto', 'webgl2'].includes(c.backend) && 'backend',
          c.scene === 'free' && !ctx.catalog.some((s) => s.name === c.free.surface) && 'surface',
          !c.edits.every((e) => [e.v, ...e.group].every((u) => Number.isInteger(u) && u >= 0 && u < 2 ** 31)
            && e.path.length > 0 && e.path.every((p) => p.length === 3 && p.every(Number.isFinite))) && 'edits',
          !c.imported.controlPoints.every((e) => e.length === 4 && Number.isInteger(e[0]) && e[0] >= 0 && e[0] < 2 ** 31 && e.slice(1).every(Number.isFinite)) && 'cp',
        ].filter(Boolean);
        if (bad.length) return { failed: `${bad.join(', ')} out of the schema for ${JSON.stringify(hash)}: ${JSON.stringify(c)}` };
        const again = cfg.readHash(cfg.writeHash(c), ctx);
        if (!same(again, c)) {
          return { failed: `writeHash/readHash is not a fixed point for ${JSON.stringify(hash)}: ${JSON.stringify(c)} vs ${JSON.stringify(again)}` };
        }
        if (hash.length > 60 && hostile.length < 40 && rand(1000) === 0) hostile.push(hash);
      }
      return { runs, hostile };
    }, RUNS);
    assert.equal(result.failed, undefined, result.failed);
    assert.equal(result.runs, RUNS);
    // The live page: each hostile hash through `hashchange`, then an ordinary scene still runs.
    for (const h of result.hostile) {
      await page.evaluate((hash) => { location.hash = hash; }, h);
    }
    await page.evaluate(() => { location.hash = '#scene=sphere-spiral&steps=2'; });
    await page.waitForFunction(() => document.querySelector('[data-testid="scene-select"]')?.value === 'sphere-spiral');
    await waitSteps(page, 2);
    await byId(page, 'step').click();
    await waitSteps(page, 3);
    assert.ok(Number((await metrics(page)).faces) > 0, 'the page runs a scene after the hostile hashes');
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});
