// Drag-to-edit figures for BENCHMARKS.md: an opened n x n quad grid (default 32 and 100), its
// middle vertex dragged 12 x 8 pixels in 20 moves 25 ms apart (PAUSE_MS=... for another pace):
// states per second while dragging and the time from release to the first finished state.
// `DUPIN_URL=... node bench-drag.mjs [n ...]`
import { dragImportedGrid, openPage } from './harness.mjs';

for (const n of (process.argv.slice(2).length ? process.argv.slice(2) : ['32', '100']).map(Number)) {
  const { browser, page } = await openPage();
  try {
    const r = await dragImportedGrid(page, n, { pause: Number(process.env.PAUSE_MS ?? 25) });
    console.log(`${n * n} quads: ${r.perSecond.toFixed(1)} states/s while dragging (pointer moves ${r.movesPerSecond.toFixed(1)}/s); ${r.settle.phase} (max planarity ${r.settle.maxPlanarity.toExponential(2)}) ${r.settle.ms.toFixed(0)} ms after release`);
  } finally {
    await browser.close();
  }
}
