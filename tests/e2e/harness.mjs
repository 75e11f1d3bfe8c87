// Shared set-up of the browser end-to-end tests: Debian's Chromium through playwright-core, with
// the flags that give headless WebGPU on SwiftShader (see DEVELOPERS.md), screenshots saved
// under target/e2e/ and pixel statistics computed in the page (no image library needed).
import { chromium } from 'playwright-core';
import AxeBuilder from '@axe-core/playwright';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const URL_BASE = process.env.DUPIN_URL ?? 'http://127.0.0.1:8080/';
export const SHOTS = join(dirname(fileURLToPath(import.meta.url)), '../../target/e2e');
mkdirSync(SHOTS, { recursive: true });

// DEVELOPERS.md's flags plus `--use-angle=swiftshader --use-vulkan=swiftshader`: without them
// headless Chromium composites in software, cannot allocate the WebGPU swap-chain image, and
// loses the whole WebGPU device on the first canvas frame (blank canvas, failing mapAsync).
const FLAGS = [
  '--headless=new', '--no-sandbox', '--enable-unsafe-webgpu', '--use-webgpu-adapter=swiftshader',
  '--enable-features=Vulkan', '--use-angle=swiftshader', '--use-vulkan=swiftshader',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run',
];

/** Opens the page (`hash` is appended to its URL: a hash, or another page of web/); with
 * `webgpu: false` the browser offers no `navigator.gpu` at all, with `adapter: false` it offers
 * one that gives no adapter; `ready: false` does not wait for
 * the configurator's first frame. `wasm` lists the wasm modules the page and its worker fetched. */
export async function openPage({ webgpu = true, adapter = true, hash = '', viewport = { width: 960, height: 640 }, ready = true } = {}) {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    args: FLAGS,
  });
  const context = await browser.newContext({ viewport, acceptDownloads: true });
  if (!webgpu) {
    await context.addInitScript(() => {
      Object.defineProperty(Navigator.prototype, 'gpu', { get: () => undefined, configurable: true });
      delete Navigator.prototype.gpu;
    });
  }
  if (!adapter) {
    // WebGPU offered but no adapter (a browser whose GPU is blocklisted).
    await context.addInitScript(() => { GPU.prototype.requestAdapter = async () => null; });
  }
  const page = await context.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  // The page fetches nothing from anywhere but its own origin.
  const origin = new URL(URL_BASE).origin;
  // The wasm modules fetched (page and worker), as paths under the page's folder.
  const wasm = [];
  page.on('request', (r) => {
    const u = new URL(r.url());
    if (!['data:', 'blob:'].includes(u.protocol) && u.origin !== origin) errors.push(`request outside the page's origin: ${r.url()}`);
    if (u.pathname.endsWith('.wasm')) wasm.push(u.pathname.slice(new URL(URL_BASE).pathname.length));
  });
  await page.goto(URL_BASE + hash);
  if (ready) await page.waitForFunction(() => document.body.dataset.ready === 'true', null, { timeout: Number(process.env.READY_MS ?? 90_000) });
  return { browser, page, errors, wasm };
}

export const byId = (page, id) => page.locator(`[data-testid="${id}"]`);

/**
 * Screenshot of the canvas, saved as target/e2e/NAME.png; returns the PNG bytes. Taken through
 * the page's own GPU readback (`window.dupin.snapshotDataUrl`), since headless Chromium leaves
 * WebGPU canvases blank in its page screenshots.
 */
export async function shot(page, name) {
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const url = await page.evaluate(() => window.dupin.snapshotDataUrl(1));
  const png = Buffer.from(url.slice(url.indexOf(',') + 1), 'base64');
  writeFileSync(join(SHOTS, `${name}.png`), png);
  return png;
}

/** Defines `window.__dupinDecodePng(base64)` -> `{ w, h, d }` (RGBA bytes) in the page, once:
 * PNGs are decoded by the browser, so the tests need no image library. */
async function installDecoder(page) {
  await page.evaluate(() => {
    window.__dupinDecodePng ??= async (s) => {
      const img = await createImageBitmap(await (await fetch(`data:image/png;base64,${s}`)).blob());
      const c = new OffscreenCanvas(img.width, img.height);
      const g = c.getContext('2d');
      g.drawImage(img, 0, 0);
      return { w: img.width, h: img.height, d: g.getImageData(0, 0, img.width, img.height).data };
    };
  });
}

/** Starts collecting the page's long tasks (over 50 ms) in `window.__long` (their durations). */
export async function watchLongTasks(page) {
  await page.evaluate(() => {
    window.__long = [];
    new PerformanceObserver((l) => window.__long.push(...l.getEntries().map((e) => e.duration))).observe({ type: 'longtask' });
  });
}

/**
 * Pixel statistics of PNG `a` (and its difference from PNG `b`), decoded in the page:
 * `covered` is the fraction of pixels farther than 8 levels from the background, taken as the
 * most frequent colour.
 */
export async function pixelStats(page, a, b = null) {
  await installDecoder(page);
  return page.evaluate(async ([a64, b64]) => {
    const decode = async (s) => (await window.__dupinDecodePng(s)).d;
    const p = await decode(a64);
    const counts = new Map();
    for (let i = 0; i < p.length; i += 4) {
      const key = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
      counts.set(key, (counts.get(key) ?? 0) + 1);
    }
    const mode = [...counts.entries()].reduce((a, b) => (b[1] > a[1] ? b : a))[0];
    const bg = [mode >> 16, (mode >> 8) & 255, mode & 255];
    let covered = 0;
    for (let i = 0; i < p.length; i += 4) {
      if (Math.max(Math.abs(p[i] - bg[0]), Math.abs(p[i + 1] - bg[1]), Math.abs(p[i + 2] - bg[2])) > 8) covered++;
    }
    let differing = null;
    if (b64) {
      const q = await decode(b64);
      differing = 0;
      for (let i = 0; i < p.length; i += 4) {
        if (Math.max(Math.abs(p[i] - q[i]), Math.abs(p[i + 1] - q[i + 1]), Math.abs(p[i + 2] - q[i + 2])) > 16) differing++;
      }
      differing /= p.length / 4;
    }
    return { covered: covered / (p.length / 4), differing };
  }, [a.toString('base64'), b ? b.toString('base64') : null]);
}

/** Drags across the canvas centre by (dx, dy) pixels. */
export async function drag(page, dx, dy) {
  const box = await byId(page, 'canvas').boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let i = 1; i <= 8; i++) await page.mouse.move(x + (dx * i) / 8, y + (dy * i) / 8);
  await page.mouse.up();
}

/** Metrics as the page shows them (the `metrics` element's data attributes). */
export async function metrics(page) {
  return page.evaluate(() => ({ ...document.querySelector('[data-testid=metrics]').dataset }));
}

/** Waits until the metrics show `steps` steps taken (each worker state bumps it). */
export async function waitSteps(page, steps, timeout = 120_000) {
  await page.waitForFunction((n) => document.querySelector('[data-testid=metrics]').dataset.steps === String(n), steps, { timeout });
}

/** Waits for the run to finish (`data-phase` = `done`). */
export async function waitDone(page, timeout = 180_000) {
  await page.waitForFunction(() => document.querySelector('[data-testid=metrics]').dataset.phase === 'done', null, { timeout });
}

/** Clicks an export button and returns the downloaded text. */
export async function exportText(page, id) {
  const [download] = await Promise.all([page.waitForEvent('download'), byId(page, id).click()]);
  return (await import('node:fs')).readFileSync(await download.path(), 'utf8');
}

/** Parses OBJ text strictly (only `v` and `f`); returns the counts. */
export function parseObj(text) {
  const lines = text.split('\n').filter(Boolean);
  const v = lines.filter((l) => l.startsWith('v ')), f = lines.filter((l) => l.startsWith('f '));
  if (v.length + f.length !== lines.length) throw new Error('OBJ has statements other than v and f');
  for (const l of v) if (l.split(' ').slice(1).map(Number).filter(Number.isFinite).length !== 3) throw new Error(`bad vertex ${l}`);
  for (const l of f) {
    const idx = l.split(' ').slice(1).map(Number);
    if (!(idx.length >= 3 && idx.every((i) => Number.isInteger(i) && i >= 1 && i <= v.length))) throw new Error(`bad face ${l}`);
  }
  return { vertices: v.length, faces: f.length };
}

/**
 * Compares PNG `actual` with the committed reference `tests/e2e/reference/NAME.png` (decoded in
 * the page): `{ differing, mean }`, the fraction of pixels farther than 24 levels in some channel
 * and the mean largest channel difference, as the native render tests measure. With
 * `DUPIN_BLESS` set, or no reference yet, `actual` becomes the reference first (look at it in
 * git before committing). A size mismatch counts as every pixel differing.
 */
export async function compareWithReference(page, actual, name) {
  const ref = join(dirname(fileURLToPath(import.meta.url)), 'reference', `${name}.png`);
  if (process.env.DUPIN_BLESS || !existsSync(ref)) {
    mkdirSync(dirname(ref), { recursive: true });
    writeFileSync(ref, actual);
  }
  const want = readFileSync(ref);
  await installDecoder(page);
  return page.evaluate(async ([a64, b64]) => {
    const [p, q] = [await window.__dupinDecodePng(a64), await window.__dupinDecodePng(b64)];
    if (p.w !== q.w || p.h !== q.h) return { differing: 1, mean: 255, size: [p.w, p.h, q.w, q.h] };
    let differing = 0, sum = 0;
    for (let i = 0; i < p.d.length; i += 4) {
      const d = Math.max(Math.abs(p.d[i] - q.d[i]), Math.abs(p.d[i + 1] - q.d[i + 1]), Math.abs(p.d[i + 2] - q.d[i + 2]));
      sum += d;
      if (d > 24) differing++;
    }
    const n = p.d.length / 4;
    return { differing: differing / n, mean: sum / n };
  }, [actual.toString('base64'), want.toString('base64')]);
}

/** An n x n noisy quad grid, 2 m spacing, +-1 mm noise, as OBJ text. */
export function gridObj(n) {
  let seed = 11;
  const rnd = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  let obj = '';
  for (let i = 0; i <= n; i++) for (let j = 0; j <= n; j++) obj += `v ${2 * i} ${2 * j} ${(rnd() - 0.5) * 0.002}\n`;
  const id = (i, j) => i * (n + 1) + j + 1;
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) obj += `f ${id(i, j)} ${id(i + 1, j)} ${id(i + 1, j + 1)} ${id(i, j + 1)}\n`;
  return obj;
}

/**
 * Opens an n x n quad grid as panels, planarises it, drags its middle vertex by (dx, dy) pixels
 * in `moves` pointer moves and measures: states per second while dragging, and the time from
 * the pointer's release to the first state that is done (page clock, state arrival).
 */
/** A bicubic NURBS dome 12 m x 12 m whose control heights are f(x) + g(y) (conjugate lines). */
export function domeJson() {
  const knots = [0, 0, 0, 0, 1, 2, 3, 3, 3, 3];
  const points = [];
  for (let i = 0; i < 6; i++) {
    const row = [];
    for (let j = 0; j < 6; j++) {
      const [x, y] = [2.4 * i - 6, 2.4 * j - 6];
      row.push([x, y, 3 - (x * x + y * y) / 24]);
    }
    points.push(row);
  }
  return JSON.stringify({ degree_u: 3, degree_v: 3, knots_u: knots, knots_v: knots, control_points: points, unit: 'm' });
}

/** Opens the n x n quad grid of `gridObj` as panels and planarises it; returns the OBJ text. */
export async function openImportedGrid(page, n) {
  const text = gridObj(n);
  await byId(page, 'import-file').setInputFiles({ name: 'grid.obj', mimeType: 'text/plain', buffer: Buffer.from(text) });
  await page.waitForFunction(() => document.querySelector('[data-testid=status]').textContent.includes('grid.obj · panels'), null, { timeout: 120_000 });
  await byId(page, 'play').click();
  await waitDone(page, 300_000);
  return text;
}

/** Page (CSS pixel) coordinates of the 3D points `points` ([x, y, z] each) in the current view. */
export function onScreen(page, points) {
  return page.evaluate((ps) => {
    const r = document.querySelector('[data-testid=canvas]').getBoundingClientRect();
    return ps.map(([x, y, z]) => {
      const q = window.dupin.viewer.project(x, y, z);
      return q ? [r.left + (q[0] + 1) / 2 * r.width, r.top + (1 - q[1]) / 2 * r.height] : null;
    });
  }, points);
}

/** The vertex positions of an OBJ text. */
export function objVertices(text) {
  return text.split('\n').filter((l) => l.startsWith('v ')).map((l) => l.split(' ').slice(1, 4).map(Number));
}

export async function dragImportedGrid(page, n, { dx = 12, dy = -8, moves = 20, pause = 25 } = {}) {
  const text = await openImportedGrid(page, n);
  const middle = (n / 2) * (n + 1) + n / 2;
  const [[ax, ay]] = await onScreen(page, [objVertices(text)[middle]]);
  const at = { x: ax, y: ay };
  await page.evaluate(() => {
    window.__up = null;
    document.querySelector('[data-testid=canvas]').addEventListener('pointerup', () => { window.__up = performance.now(); }, { once: true });
  });
  await byId(page, 'edit-vertices').click();
  const s0 = await page.evaluate(() => window.dupin.stepLog.length);
  const t0 = Date.now();
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  for (let i = 1; i <= moves; i++) {
    await page.mouse.move(at.x + (dx * i) / moves, at.y + (dy * i) / moves);
    await page.waitForTimeout(pause);
  }
  const seconds = (Date.now() - t0) / 1000;
  const states = (await page.evaluate(() => window.dupin.stepLog.length)) - s0;
  await page.mouse.up();
  // The state that finishes the run for the last position sent (an earlier position's run may
  // finish after the release too; the last one's before it, when the release adds no move).
  await page.waitForFunction(() => window.__up !== null && !window.dupin.dragPending, null, { timeout: 300_000 });
  const settle = await page.evaluate(() => {
    // The run for the last position may have finished before the release (0 ms then).
    const e = window.dupin.stepLog.find((x) => x.dragSeq === window.dupin.dragSeq && x.phase !== 'perturb');
    return { ms: Math.max(0, e.at - window.__up), phase: e.phase, maxPlanarity: e.maxPlanarity };
  });
  return { middle, pointer: [at.x + dx, at.y + dy], perSecond: states / seconds, movesPerSecond: moves / seconds, settle };
}

/** The serious and critical violations; every violation is tallied by impact in the log. */
export async function axeSerious(page, where = '') {
  const r = await new AxeBuilder({ page }).analyze();
  const tally = {};
  for (const v of r.violations) tally[v.impact] = (tally[v.impact] ?? 0) + v.nodes.length;
  console.log(`# axe, ${where}: ${r.passes.length} rules pass, violations by impact ${JSON.stringify(tally)} (${r.violations.map((v) => v.id).join(', ') || 'none'})`);
  return r.violations
    .filter((v) => ['serious', 'critical'].includes(v.impact))
    .map((v) => `${v.id} (${v.impact}): ${v.nodes.slice(0, 3).map((n) => n.target.join(' ')).join(' | ')}`);
}
