// The page's side of rhino-worker.js: Rhino .3dm files in and out. The worker (and rhino3dm's
// 2.6 MB module) starts on the first .3dm opened or written.
let worker = null;
let next = 0;
const pending = new Map();

function call(message, transfer = []) {
  if (!worker) {
    worker = new Worker(new URL('./rhino-worker.js', import.meta.url), { type: 'module' });
    worker.addEventListener('message', (e) => {
      const { id, error } = e.data;
      const p = pending.get(id);
      pending.delete(id);
      if (error) p?.reject(new Error(error));
      else p?.resolve(e.data);
    });
    worker.addEventListener('error', (e) => {
      // rhino3dm failed to load: every waiting call fails, the next call starts afresh.
      for (const p of pending.values()) p.reject(new Error(`rhino3dm could not start (${e.message ?? 'worker error'})`));
      pending.clear();
      worker.terminate();
      worker = null;
    });
  }
  const id = ++next;
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    worker.postMessage({ id, ...message }, transfer);
  });
}

/** Reads a .3dm: `{ unit, kind: 'surface' | 'mesh', name, text, note }` where `text` is the
 * design as NURBS JSON (a surface) or OBJ (meshes) and `unit` the file's (`null`: none). */
export async function read3dm(bytes, name) {
  return (await call({ read: bytes, name })).design;
}

/** Writes panels (`Session.exportPanels`) as .3dm: `{ bytes, degenerate }`, the panels too
 * degenerate for a planar surface (written as their outline only). */
export async function write3dm(panels) {
  const { bytes, degenerate } = await call({ write: panels });
  return { bytes, degenerate };
}
