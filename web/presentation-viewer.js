// The script of a shared presentation file (share.js inlines it). A classic script, not a
// module: a file opened from disk cannot import modules. It reads the blocks share.js wrote
// (certificate, camera, and gzip+base64 design and the viewer-only module's two builds), fills in
// the certificate, runs the build this browser can draw with (WebGPU only, or the one with
// WebGL2 where there is no WebGPU adapter: its wasm-bindgen `no-modules` glue as a script
// element, which defines the global `wasm_bindgen`) and draws the panels with its `Presenter`:
// drag to orbit (it coasts), wheel to zoom. `document.body.dataset.state` is `loading`,
// `ready` (with `readyMs`, from navigation to the first drawn view) or `error`, and
// `window.dupinPresentation.snapshotDataUrl()` reads the view back (for tests).
/* global wasm_bindgen */
(async () => {
  const byId = (id) => document.getElementById(id);
  const block = (id) => byId(id).textContent.trim();
  const status = byId('status');
  const say = (text, isError = false) => { status.textContent = text; status.classList.toggle('error', isError); };

  async function inflate(base64) {
    const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  const cert = JSON.parse(block('dupin-certificate'));
  const rows = byId('cert-rows');
  for (const [k, v] of cert.rows) {
    const dt = document.createElement('dt');
    dt.textContent = k;
    const dd = document.createElement('dd');
    dd.textContent = v;
    dd.dataset.row = k.replaceAll(' ', '-');
    if (k === 'status' && cert.warning) dd.classList.add('warning');
    rows.append(dt, dd);
  }

  // The figures fold away, so the client can see the whole design; the title stays.
  const toggle = byId('cert-toggle');
  toggle.addEventListener('click', () => {
    const open = rows.hidden;
    rows.hidden = !open;
    toggle.setAttribute('aria-expanded', String(open));
    toggle.textContent = open ? 'Hide figures' : 'Show figures';
  });

  const canvas = byId('view');
  try {
    let webgpu = false;
    try { webgpu = !!(await navigator.gpu?.requestAdapter()); } catch { /* no WebGPU: WebGL2 */ }
    const suffix = webgpu ? '' : '-gl';
    const glue = document.createElement('script');
    glue.textContent = new TextDecoder().decode(await inflate(block(`dupin-glue${suffix}`)));
    document.head.append(glue);
    await wasm_bindgen({ module_or_path: await inflate(block(`dupin-wasm${suffix}`)) });
    const mesh = wasm_bindgen.designMesh(new TextDecoder().decode(await inflate(block('dupin-design'))));
    const presenter = await wasm_bindgen.Presenter.create(canvas, false);
    const fit = () => {
      const dpr = Math.min(window.devicePixelRatio || 1, 2);
      const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
      const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
      if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; presenter.resize(w, h); }
    };
    fit();
    // The panels and their frames; the offset layer's figures are in the certificate.
    const info = presenter.setMesh(mesh, false);
    mesh.free();
    const camera = JSON.parse(block('dupin-camera'));
    // The view it was shared from; a camera the module refuses leaves the framing view.
    if (camera) { try { presenter.setCamera(camera); } catch (e) { console.warn(`camera not restored: ${e.message}`); } }

    let dirty = true, last = null, lastT = performance.now();
    const frame = (t) => {
      const dt = t - lastT;
      lastT = t;
      fit();
      if (presenter.tick(dt)) dirty = true;
      presenter.poll();
      if (dirty) { dirty = false; presenter.render(); }
      requestAnimationFrame(frame);
    };
    canvas.addEventListener('pointerdown', (e) => { last = [e.clientX, e.clientY, e.timeStamp]; presenter.stop(); canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointermove', (e) => {
      if (!last) return;
      presenter.orbit((e.clientX - last[0]) * 0.01, (e.clientY - last[1]) * 0.01, e.timeStamp - last[2]);
      last = [e.clientX, e.clientY, e.timeStamp];
      dirty = true;
    });
    for (const ev of ['pointerup', 'pointercancel']) canvas.addEventListener(ev, () => { last = null; });
    canvas.addEventListener('wheel', (e) => { e.preventDefault(); presenter.zoom(Math.exp(e.deltaY * 0.001)); dirty = true; }, { passive: false });
    new ResizeObserver(() => { dirty = true; }).observe(canvas);
    byId('full-screen').addEventListener('click', () => document.documentElement.requestFullscreen?.());
    requestAnimationFrame(frame);
    // For tests and scripts: the view as a PNG data URL, read back from the GPU (headless
    // Chromium leaves WebGPU canvases blank in its own screenshots).
    window.dupinPresentation = {
      snapshotDataUrl: async (scale = 1) => {
        const image = await presenter.snapshot(scale);
        const c = new OffscreenCanvas(image.width, image.height);
        c.getContext('2d').putImageData(image, 0, 0);
        const blob = await c.convertToBlob({ type: 'image/png' });
        return new Promise((resolve) => { const r = new FileReader(); r.onload = () => resolve(r.result); r.readAsDataURL(blob); });
      },
    };
    say(`${info.panels} panels · ${info.beams} beams · ${presenter.backend}${info.offsetError ? ` · ${info.offsetError}` : ''}`, !!info.offsetError);
    document.body.dataset.readyMs = performance.now().toFixed(0);
    document.body.dataset.state = 'ready';
  } catch (e) {
    say(`This presentation cannot be shown here: ${e?.message ?? e}. It needs a current browser with WebGPU or WebGL2.`, true);
    document.body.dataset.state = 'error';
  }
})();
