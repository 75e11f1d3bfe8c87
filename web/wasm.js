// The page's wasm module, loaded once for every page script that uses it. The crate is built
// twice (`cargo xtask build-web`): `pkg/` draws with WebGPU only, and `pkg-gl/` adds wgpu's
// WebGL2 backend, whose WGSL-to-GLSL translator (naga) and wgpu-core make it 4.5 MB instead of
// 2.05 MB (BENCHMARKS.md). A browser that offers WebGPU gets `pkg/`; one that does not, or a URL
// asking for WebGL2 (`backend=webgl2`), gets `pkg-gl/`. The solver worker loads the page's build
// (`workerUrl`), so the browser fetches one module, not two.
//
// Why the page does not ask for a WebGPU adapter before choosing: the first request starts the
// GPU process (140-480 ms on SwiftShader), and wgpu asks again when the view opens, so asking
// first put that time before the module's download instead of beside it. A browser that offers
// WebGPU but has no adapter is told by the view (`openView`), which then loads `pkg-gl/`.

/** True when the URL asks for WebGL2 (`#...&backend=webgl2`), as `readHash` reads it. */
export const forcedWebgl2 = new URLSearchParams(location.hash.slice(1)).get('backend') === 'webgl2';

/** `'gl'` (the WebGL2 build, `pkg-gl/`) or `'webgpu'` (`pkg/`); null until `loadWasm`. */
export let build = null;

/** The module's exports, initialised; null until `loadWasm` resolves (a live binding). */
export let wasm = null;

/** Imports and initialises build `which`; resolves to its exports. */
async function load(which) {
  const module = await import(which === 'gl' ? './pkg-gl/dupin_web.js' : './pkg/dupin_web.js');
  await module.default();
  [build, wasm] = [which, module];
  return module;
}

/** Picks the build, imports and initialises it; resolves to its exports. */
export function loadWasm() {
  return load(forcedWebgl2 || !navigator.gpu ? 'gl' : 'webgpu');
}

/**
 * Opens a view with `open(exports)` (e.g. `(w) => w.Viewer.create(canvas, forcedWebgl2)`). Where
 * the WebGPU build cannot (the browser offers WebGPU but gives no adapter or device), loads the
 * WebGL2 build and opens it with that. Resolves to `{ view, exports }`: `exports` changed when
 * the build did (objects of one build do not mix with the other's).
 */
export async function openView(open) {
  try {
    return { view: await open(wasm), exports: wasm };
  } catch (e) {
    if (build !== 'webgpu') throw e;
    console.warn(`WebGPU is offered but did not open (${e.message ?? e}): loading the WebGL2 build`);
    const exports = await load('gl');
    return { view: await open(exports), exports };
  }
}

/** The solver worker's URL: the worker loads the page's build. */
export function workerUrl() {
  const url = new URL('./worker.js', import.meta.url);
  url.searchParams.set('build', build ?? 'webgpu');
  return url;
}
