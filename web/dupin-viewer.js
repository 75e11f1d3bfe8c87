// <dupin-viewer src="design.json">: a Dupin design embedded in any web page, read-only. The
// element loads Dupin's viewer-only wasm module (`pkg-viewer/` beside this file, once per page:
// the renderer without the solvers), fetches `src` (a design as the page's JSON export writes
// it, or a bare { vertices, faces }), and draws its panels coloured by planarity with WebGPU, or
// with WebGL2 where the browser has no WebGPU adapter: then it loads the module's WebGL2 build
// (`pkg-viewer-gl/`) instead. Drag to orbit, wheel to zoom. The module's glue is a classic script
// that defines the global `wasm_bindgen`.
//
//   <script type="module" src="dupin-viewer.js"></script>
//   <dupin-viewer src="examples/conical-station.json" style="width: 640px; height: 400px"></dupin-viewer>
//
// State for scripts and tests: `data-state` is `loading`, `ready` or `error`; a `load` event
// carries { faces, backend }, an `error` event { message } (the message is also shown inside).
/* global wasm_bindgen */
let wasm = null; // one module for every element of the page: resolves to its exports

async function hasWebGpuAdapter() {
  try { return !!(await navigator.gpu?.requestAdapter()); } catch { return false; }
}

/** Loads the viewer-only module (its WebGL2 build without WebGPU): its glue as a script element, then its wasm. */
async function loadModule() {
  const PKG = new URL(await hasWebGpuAdapter() ? 'pkg-viewer/' : 'pkg-viewer-gl/', import.meta.url);
  return new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = new URL('dupin_viewer.js', PKG).href;
    script.onload = resolve;
    script.onerror = () => reject(new Error(`${script.src}: not loaded`));
    document.head.append(script);
  }).then(async () => {
    // A global lexical binding of the classic script (`let`), not a property of globalThis.
    await wasm_bindgen({ module_or_path: new URL('dupin_viewer_bg.wasm', PKG) });
    return wasm_bindgen;
  });
}
let sheet = null; // one style sheet for every element

const STYLE = `
  :host { display: block; position: relative; width: 480px; height: 320px; background: #0b0c10; }
  canvas { width: 100%; height: 100%; display: block; touch-action: none; cursor: grab; }
  p { position: absolute; left: 8px; bottom: 4px; margin: 0; font: 12px system-ui, sans-serif; color: #8d93a3; }
  p.error { color: #ff7b72; }
`;

class DupinViewer extends HTMLElement {
  static observedAttributes = ['src'];

  constructor() {
    super();
    const root = this.attachShadow({ mode: 'open' });
    // A constructed sheet, not a <style> element: pages whose CSP forbids inline styles (this
    // project's own) still style the element.
    sheet ??= new CSSStyleSheet();
    if (!sheet.cssRules.length) sheet.replaceSync(STYLE);
    root.adoptedStyleSheets = [sheet];
    this.canvas = document.createElement('canvas');
    this.canvas.setAttribute('role', 'img');
    this.note = document.createElement('p');
    this.note.setAttribute('role', 'status');
    root.append(this.canvas, this.note);
    this.viewer = null;
    this.loads = 0;
    this.frame = 0;
  }

  connectedCallback() {
    this.wire();
    if (this.getAttribute('src')) this.load();
  }

  attributeChangedCallback(name, old, value) {
    if (this.isConnected && old !== null && old !== value) this.load();
  }

  /** Reads `src` and shows it; a later call wins over an earlier one still loading. */
  async load() {
    const ticket = ++this.loads;
    const src = this.getAttribute('src');
    this.dataset.state = 'loading';
    this.say(`loading ${src}…`);
    try {
      wasm ??= loadModule();
      // A failed load is tried again by the next element or `src`.
      const { Viewer, designMesh } = await wasm.catch((e) => { wasm = null; throw e; });
      const response = await fetch(src);
      if (!response.ok) throw new Error(`${src}: HTTP ${response.status}`);
      const mesh = designMesh(await response.text());
      if (ticket !== this.loads) { mesh.free(); return; }
      this.fit();
      this.viewer ??= await Viewer.create(this.canvas, false);
      this.viewer.resize(this.canvas.width, this.canvas.height);
      this.viewer.setMesh(mesh, true);
      const count = mesh.panelCount;
      mesh.free();
      this.canvas.setAttribute('aria-label', `${count} panels, coloured by planarity; drag to orbit`);
      this.draw();
      this.dataset.state = 'ready';
      this.say(`${count} panels · ${this.viewer.backend}`);
      this.dispatchEvent(new CustomEvent('load', { detail: { faces: count, backend: this.viewer.backend } }));
    } catch (e) {
      if (ticket !== this.loads) return;
      const message = String(e?.message ?? e);
      this.dataset.state = 'error';
      this.say(message, true);
      this.dispatchEvent(new CustomEvent('error', { detail: { message } }));
    }
  }

  say(text, isError = false) {
    this.note.textContent = text;
    this.note.classList.toggle('error', isError);
  }

  fit() {
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    this.canvas.height = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
  }

  /** One frame on the next animation frame (coalesced). */
  draw() {
    if (this.frame || !this.viewer) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      try { this.viewer.render(); } catch (e) { this.say(String(e?.message ?? e), true); }
    });
  }

  wire() {
    if (this.wired) return;
    this.wired = true;
    let last = null;
    this.canvas.addEventListener('pointerdown', (e) => { last = [e.clientX, e.clientY]; this.canvas.setPointerCapture(e.pointerId); });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!last || !this.viewer) return;
      this.viewer.orbit((e.clientX - last[0]) * 0.01, (e.clientY - last[1]) * 0.01);
      last = [e.clientX, e.clientY];
      this.draw();
    });
    const up = () => { last = null; };
    this.canvas.addEventListener('pointerup', up);
    this.canvas.addEventListener('pointercancel', up);
    this.canvas.addEventListener('wheel', (e) => {
      if (!this.viewer) return;
      e.preventDefault();
      this.viewer.zoom(Math.exp(e.deltaY * 0.001));
      this.draw();
    }, { passive: false });
    new ResizeObserver(() => {
      if (!this.viewer) return;
      this.fit();
      this.viewer.resize(this.canvas.width, this.canvas.height);
      this.draw();
    }).observe(this.canvas);
  }
}

customElements.define('dupin-viewer', DupinViewer);
